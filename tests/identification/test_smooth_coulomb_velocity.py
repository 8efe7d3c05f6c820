"""A smooth Coulomb term ``tanh(q̇/v_s)`` is fitted only on rows at least twice ``v_s`` fast, in the cross-validation that
chooses it and in the estimation (:mod:`dynid.identification.friction_models`, issue "Honest on any log").

A UR10e simulated in MuJoCo (outside dynid's model, tests/mujoco_logs.py) under its PID loop, with dry friction
``fc·sign(q̇)`` applied as a force: at rest and near it the loop chatters, so the measured friction is smooth below
the joints' slowest moves. Identified on 20 s of point-to-point moves with rests, J4 is given ``tanh(q̇/v_s)`` with
``v_s`` twice its ``min_speed``. Fitted on every row above ``min_speed``, where the term is not yet Coulomb-like, its
coefficient traded with the viscous one (fv4 0.28 N·m·s/rad against the truth's 0.56, fc4 1.20 against 1.10)."""

from importlib import resources

import numpy as np

from dynid.identification.run import run_identification
from dynid.io.config.identification_config import load_identification_config

from ..mujoco_logs import Drives, simulate, write_csv

DRIVES = Drives(ia=np.array([0.066, 0.066, 0.03, 0.011, 0.011, 0.011]), fv=np.array([3.3, 3.3, 1.5, 0.56, 0.56, 0.56]),
                fc=np.array([6.6, 6.6, 3.0, 1.1, 1.1, 1.1]))
"""Drive terms of the size the zoo gives an arm with the UR10e's torque limits (benchmarks/zoo)."""


def test_a_smooth_coulomb_term_is_coulomb_like_on_every_row_the_estimation_fits(tmp_path):
    urdf = (resources.files("dynid.model") / "robots" / "ur10e.urdf").read_text()
    (tmp_path / "ur10e.urdf").write_text(urdf)
    rng = np.random.default_rng(4)
    common = dict(noise_share=0.02, torque_std=np.array([1.0, 2.0, 1.0, 0.2, 0.2, 0.2]), dry="sign",
                  centre=np.array([0, -1.5, 1.2, -1.2, 0, 0]), amplitude=0.5)
    write_csv(tmp_path / "ptp.csv", simulate(urdf, DRIVES, "ptp", 20.0, rng, **common))
    cols = lambda a: "[" + ", ".join(str(a + j) for j in range(6)) + "]"  # noqa: E731
    (tmp_path / "c.toml").write_text(
        f'data_root = "{tmp_path}"\n[robot]\nurdf = "ur10e.urdf"\ndrive_terms = ["Ia", "fc", "fv", "offset"]\n'
        f'[identification]\nfile = "ptp.csv"\ntime = {{ column = 1 }}\npositions = {{ columns = {cols(2)} }}\n'
        f'torques = {{ columns = {cols(8)} }}\n[estimation]\nestimators = ["wls"]\n')
    result = run_identification(load_identification_config(tmp_path / "c.toml"), validate=False)
    models = result.settings["friction_models"]["models"]
    min_speed = np.broadcast_to(result.settings["preprocessing"]["min_speed"], (6,))
    smooth = [j for j, m in enumerate(models) if m["kind"] == "smooth"]
    assert smooth, [m["kind"] for m in models]  # the case this test is about: smooth Coulomb terms were chosen
    for j in smooth:
        assert min_speed[j] >= 2 * models[j]["velocity"] * (1 - 1e-9), (j + 1, models[j]["velocity"], min_speed[j])
    assert "smooth Coulomb term slower than 2" in result.settings["preprocessing"]["derivation"]
    # J4's Coulomb and viscous friction from the drive-only fit (the description's links are the truth's)
    names, phi = result.base.names, result.drive_only.params
    fc4, fv4 = phi[names.index("fc4")], phi[names.index("fv4")]
    assert abs(fc4 / DRIVES.fc[3] - 1) < 0.05, fc4
    assert abs(fv4 / DRIVES.fv[3] - 1) < 0.15, fv4
    # derived min_speed: said in the derivation only; a min_speed the user gave: a warning says it was raised, and where
    assert not any("min_speed raised" in w for w in result.warnings)
    config = tmp_path / "c.toml"
    config.write_text(config.read_text() + "[preprocessing]\nmin_speed = 0.004\n")
    given = run_identification(load_identification_config(config), validate=False)
    raised = [w for w in given.warnings if "preprocessing.min_speed raised" in w]
    chosen = [j for j, m in enumerate(given.settings["friction_models"]["models"]) if m["kind"] == "smooth"]
    assert len(raised) == 1 and all(f"J{j + 1} " in raised[0] for j in chosen if 2 * given.settings[
        "friction_models"]["models"][j]["velocity"] > 0.004), raised
