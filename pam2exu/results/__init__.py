"""Results: the table of named columns, CSV, selection of outputs, comparison, plots."""
from ..errors import CompareInputError
from .compare import compare
from .comparison import Comparison, VariableComparison
from .plot import plot
from .info import RunInfo
from .reading import read_csv, read_names
from .names import select_columns
from .table import Results

__all__ = ["Results", "select_columns", "read_csv", "plot", "compare", "Comparison",
           "VariableComparison", "CompareInputError", "read_names", "RunInfo"]
