"""Results: the table of named columns, CSV, selection of outputs."""
from .table import Results, select_columns

__all__ = ["Results", "select_columns"]
