"""Hand-written reference solutions that pam2exu's results are checked against.

Closed forms and Newton–Euler solutions, derived in the docstrings and computed with NumPy
alone: nothing here imports pam2exu (``actuator_law`` and ``model_toml`` read or write a
model's plain data). The tests (tests/analyses/) and the benchmark
(benchmarks/speed_vs_error.py) both import them from here, so that neither imports the other.

- ``laws``: the actuators' time laws and ``actuator_law``.
- ``closed_form``: the columns of a solid, the error measure ``errors``, the four-bar
  (``four_bar``, ``FOUR_BAR``).
- ``slider_crank``: the offset slider-crank: closed-form kinematics, its 12 Newton–Euler
  equations (``newton_euler``), the model as TOML (``model_toml``).
- ``revolute``: Newton–Euler for mechanisms of revolute joints and angular motors
  (``revolute_newton_euler``, checked by its power balance).
- ``pendulum``: a compound pendulum, free or on a driven slider, as TOML, and its one-DOF
  equation integrated by DOP853 (the dynamic, natural-dynamics and energy tests).
- ``andrews``: Andrews' squeezing mechanism, the IVP test set's published state at 0.03 s
  and its equations integrated by DOP853 (tests/analyses/test_andrews.py,
  benchmarks/dynamics.py).

This package sits at the repository root and is not installed with pam2exu. pytest finds it
through ``pythonpath = ["."]`` (pyproject.toml); benchmarks/speed_vs_error.py puts the
repository root on ``sys.path`` itself.
"""
