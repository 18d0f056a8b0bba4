import pytest

from plantmech.design import DesignError, load_design
from tests.conftest import EXAMPLES


def test_examples_load():
    for f in EXAMPLES.glob("*.toml"):
        d = load_design(f)
        if d.mechanism == "sugarcane_seeder":
            assert len(d.trajectory.points) == 27
        else:
            assert d.carrier.arms in (2, 3)


def write(tmp_path, text):
    p = tmp_path / "d.toml"
    p.write_text(text)
    return p


def base(**over):
    src = (EXAMPLES / "sugarcane_seeder.toml").read_text()
    for k, v in over.items():
        src = src.replace(k, v)
    return src


def test_missing_field_is_named(tmp_path):
    p = write(tmp_path, base(**{"e = 4\n": ""}))
    with pytest.raises(DesignError, match=r"field 'trajectory.sections.e': required"):
        load_design(p)


def test_wrong_type_is_named(tmp_path):
    p = write(tmp_path, base(**{"[429.49, -220.00]": '["x", -220.00]'}))
    with pytest.raises(DesignError, match=r"trajectory.points.0.0") as exc:
        load_design(p)
    assert str(p) in str(exc.value)


def test_nan_and_negative_are_refused(tmp_path):
    p = write(tmp_path, base(**{"min_pitch_radius_mm = 5.0": "min_pitch_radius_mm = -1"}))
    with pytest.raises(DesignError, match=r"gear_train.min_pitch_radius_mm"):
        load_design(p)
    p = write(tmp_path, base(**{"[429.49, -220.00]": "[nan, -220.00]"}))
    with pytest.raises(DesignError, match=r"trajectory.points.0.0"):
        load_design(p)


def test_section_index_out_of_range(tmp_path):
    p = write(tmp_path, base(**{"a = 20": "a = 40"}))
    with pytest.raises(DesignError, match=r"sections.a = 40 but there are only 27 points"):
        load_design(p)


def test_unknown_field_and_mechanism(tmp_path):
    p = write(tmp_path, base(**{"split_exponent": "split_exponnent"}))
    with pytest.raises(DesignError, match=r"gear_train.split_exponnent': unknown field"):
        load_design(p)
    p = write(tmp_path, base(**{'mechanism = "sugarcane_seeder"': 'mechanism = "lawnmower"'}))
    with pytest.raises(DesignError, match=r"unknown mechanism 'lawnmower'"):
        load_design(p)


def test_bad_toml_and_missing_file(tmp_path):
    p = write(tmp_path, "mechanism = [")
    with pytest.raises(DesignError, match="not valid TOML"):
        load_design(p)
    with pytest.raises(DesignError, match="no such design file"):
        load_design(tmp_path / "nope.toml")
