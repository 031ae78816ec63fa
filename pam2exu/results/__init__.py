"""Results: the table of named columns, CSV, selection of outputs, comparison, plots."""
from .compare import CompareInputError, Comparison, VariableComparison, compare, read_names
from .plot import plot
from .table import Results, read_csv, select_columns

__all__ = ["Results", "select_columns", "read_csv", "plot", "compare", "Comparison",
           "VariableComparison", "CompareInputError", "read_names"]
