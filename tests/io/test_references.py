import numpy as np
import pytest

from dynid.dynamics.base_parameters import base_parameters
from dynid.exceptions import DataError
from dynid.io.config.references import load_reference, parse_expression
from dynid.model.description import load_robot


def test_parse_expression_with_aliases_and_exponents():
    names = ("ZZ1", "Ia1", "YY2", "MZ3", "M3")
    np.testing.assert_allclose(parse_expression("Izz1 + 1.0*Ia1 - 0.07*mz3 + 1e-05*m3", names, "x"), [1, 1, 0, -0.07, 1e-5])
    for bad, msg in (("Izz1 +* 2", "cannot read"), ("foo1", "unknown parameter term"), ("Ixx2", "does not have"), (" ", "empty")):
        with pytest.raises(DataError, match=msg):
            parse_expression(bad, names, "x")


def test_standard_set_becomes_base_parameters(tmp_path):
    robot = load_robot("er16").submodel(3)
    base = base_parameters(robot, rng=0)
    phi = np.random.default_rng(0).normal(size=robot.n_params)
    rows = ["name,value"] + [f"{n.replace('XX', 'Ixx').replace('MX', 'mx')},{float(v)!r}" for n, v in zip(robot.parameter_names, phi)] + ["K1,3.0", "foo,1.0"]
    (tmp_path / "ref.csv").write_text("\n".join(rows) + "\n")
    ref = load_reference({"name": "r", "file": "ref.csv", "header": True, "names": "name", "values": "value"}, tmp_path, "cfg", base)
    np.testing.assert_allclose(ref.beta, base.base_from_standard(phi))
    assert ref.warnings and "foo" in ref.warnings[0] and "K1" not in ref.warnings[0]  # drive gains beside a set: no warning
    (tmp_path / "ref.csv").write_text("\n".join(rows[:-4]) + "\n")
    with pytest.raises(DataError, match="lacks parameter"):
        load_reference({"name": "r", "file": "ref.csv", "header": True, "names": "name", "values": "value"}, tmp_path, "cfg", base)


def test_base_set_matched_to_dynid_regrouping(tmp_path):
    robot = load_robot("er16").submodel(3)
    base = base_parameters(robot, rng=0)
    beta = np.arange(base.n_base) + 1.0
    lines = [f"\"{e.split(' = ', 1)[1].replace('·', '*')}\",{b},{2 * b}" for e, b in zip(base.expressions, beta)]
    (tmp_path / "bp.csv").write_text("\n".join(lines[::-1]) + "\n")  # any order
    ref = load_reference({"name": "r", "file": "bp.csv", "format": "base", "names": 1, "values": 2, "rel_std": 3}, tmp_path, "cfg", base)
    np.testing.assert_allclose(ref.beta, beta)
    np.testing.assert_allclose(ref.relative_std, 2 * beta)
    (tmp_path / "bp.csv").write_text("\n".join(lines[1:]) + "\n")
    with pytest.raises(DataError, match=f"do not determine the base parameter.*{base.names[0]}"):
        load_reference({"name": "r", "file": "bp.csv", "format": "base", "names": 1, "values": 2}, tmp_path, "cfg", base)


def test_nominal_reference_is_the_descriptions_own_values(tmp_path):
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.io.config.references import load_reference
    from dynid.model.description import load_robot

    robot = load_robot("er16")
    base = base_parameters(robot, rng=0)
    ref = load_reference({"name": "nominal", "format": "nominal"}, tmp_path, "cfg: references[0]", base,
                         robot.standard_parameters())
    np.testing.assert_allclose(ref.beta, base.regrouping @ robot.standard_parameters())
