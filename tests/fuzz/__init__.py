"""A seeded mutation fuzzer of pam2exu's model files (issue 10).

``mutants``: the generator, ``mutant(seed) -> (name, bytes, description)``.
``runner``: runs one case and classifies it; ``campaign`` runs many on worker processes;
``python -m tests.fuzz.runner --count 10000 --workers 2 --seed 0 [--report out.md]``.
"""
