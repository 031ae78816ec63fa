"""Results: the table of named columns, CSV, selection of outputs, comparison."""
from .compare import CompareInputError, Comparison, VariableComparison, compare, read_names
from .table import Results, select_columns

__all__ = ["Results", "select_columns", "compare", "Comparison", "VariableComparison",
           "CompareInputError", "read_names"]
