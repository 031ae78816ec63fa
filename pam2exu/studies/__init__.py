"""Studies: one analysis of one model, run for many variants of its values."""
