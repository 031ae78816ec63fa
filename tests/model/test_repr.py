"""``print(model)``: one line saying what the model is (issue 22; it showed a bare
``<pam2exu.model.model.Model object at 0x…>``)."""
import pam2exu

ROOT = pam2exu.__file__.replace("pam2exu/__init__.py", "")


def test_print_model_says_name_file_counts_and_analysis():
    path = ROOT + "examples/four_bar.toml"
    model = pam2exu.load(path)
    assert str(model) == repr(model) == (
        f"<Model 'four-bar' from {path}: 4 solids, 6 elements; kinematic analysis, "
        "t = 0 … 1 s in 200 steps>")
    clearance = pam2exu.load(ROOT + "examples/clearance/locomotive.toml")
    assert ": 5 solids, 8 elements, 2 variations; clearance analysis, t = 0 … " \
        in repr(clearance)


def test_repr_of_a_model_being_built_or_wrong():
    """A model made in Python has no file; one at t = 0 only has no interval; a bad
    setting is shown as given, never raised."""
    m = pam2exu.Model("demo")
    m.add_solid("crank", points={"O": [0, 0]})
    assert repr(m) == "<Model 'demo': 1 solid, 0 elements; kinematic analysis, t = 0 … 1 s " \
                      "in 100 steps>"
    m.analysis.type = "assembly"
    assert repr(m).endswith("; assembly analysis>")
    m.analysis.type, m.analysis.t_end = "kinematic", "one second"
    assert repr(m).endswith("kinematic analysis, t_end = 'one second', steps = 100>")
