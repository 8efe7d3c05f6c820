"""The check of a log's geometry against the robot file (``dynid.validation.geometry_checks``) on real logs: what it
names and what it leaves, with the figures its rule reads.

Cases, each prepared as ``dynid identify`` prepares it (its config's preprocessing):
- the four real logs and the TX40's whole-motion config as configured (``configs/``), and the 36 windows of 3-6 s of
  ``benchmarks/short_windows.py`` (``--alone`` and ``--fresh``'s): nothing must be named;
- the TX40's log without the built-in description's offsets (-π/2 on J2, +π/2 on J3, which FIGAROH applies);
- quarter and half turns put on J2, J3 and J4 of the UR10e's and J2, J3, J4 and J6 of the LBR Med7's logs (through
  ``position_offset``), four pairs of the Med7's position columns swapped, and five pairs of its joints' position and
  torque columns both swapped: each must be named as its inverse, where it changes the torque;
- the UR10e's and the Med7's logs read with a description whose gravity is along +x or -y (a wall): each must be
  named as the floor's gravity; along +z (a ceiling) it only flips the gravity torques, which the sign check names;
- the Med7's log (100 Hz) read at 1000, 200 and 50 Hz, and the TX40's (5 kHz) at 50 kHz: each is expected named as
  the motion that many times slower but at 50 Hz (the motion half as fast leaves what the log leaves as read); two
  miss (benchmarks/README.md: the Med7's slow log at 200 Hz leaves too little to search, the TX40's rough
  description explains too little either way);
- J2, J3, J4 and J6 of the Med7 counted the other way round (its positions' sign, and its positions' and its torque's):
  each must be named as reversed (or beside a twin the torques cannot tell from it), but the wrist's J6, whose angle
  hardly changes the torque, and J3, about which the LBR's links are nearly symmetric (its reversal leaves 0.35 % of
  the torque, the log as recorded 0.30 %).

From the repository root, with the shared data beside it: ``.venv/bin/python benchmarks/geometry_checks.py`` (about a
minute). It prints one row per case: the share of the torque beyond the nuisance columns that the description's
nominal model leaves with the logged angles, the closest change and the share it leaves, their ratio (named at
``CHANGE_GAIN`` or less), and the change named.
"""

from __future__ import annotations

import re
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

TURNS = ("pi/2", "-pi/2", "pi")


def _prepared(config):
    """The config's identification log, prepared as ``dynid identify`` prepares it, and the robot it is fitted with."""
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.identification.run import pipeline_of
    from dynid.io.logs.datasets import load_recording

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        base = base_parameters(config.robot, rng=0)
        prepared = pipeline_of(config).prepare(load_recording(config.identification, config.robot), base, lambda s: None)
    return prepared.robot, prepared.data


def _row(label: str, config, expected: str) -> bool:
    """One case's row; whether what was named is what was expected ("" for nothing)."""
    from dynid.validation.geometry_checks import UNEXPLAINED_FROM, geometry_findings

    robot, data = _prepared(config)
    found, stats = geometry_findings(robot, data.q, data.dq, data.ddq, data.tau, "log")
    if found and found[0].kind == "rate":
        named = f"rate ×{stats['time_scale']:.3g}"  # the log read at that many times its rate
        ratio = stats["unexplained_time_scaled"] / stats["unexplained"]
        print(f"| {label} | {100 * stats['unexplained']:.3g} | motion {stats['time_scale']:.3g}× slower | "
              f"{100 * stats['unexplained_time_scaled']:.3g} | {ratio:.2f} | {named} | "
              f"{'yes' if named == expected else 'NO: expected ' + (expected or 'nothing')} |", flush=True)
        return named == expected
    named = _change(stats) if found else ""
    twin = _change(stats["twin"]) if found and "twin" in stats else ""
    if "time_scale" in stats:  # the time scale tried first: its closest, beside the geometry's
        print(f"<!-- {label}: time scale {stats['time_scale']:.3g}, ratio "
              f"{stats['unexplained_time_scaled'] / stats['unexplained']:.2f} -->")
    if "unexplained_changed" in stats:
        ratio = stats["unexplained_changed"] / stats["unexplained"]
        figures = f"{100 * stats['unexplained']:.3g} | {_change(stats)} | {100 * stats['unexplained_changed']:.3g} | {ratio:.2f}"
    else:
        why = ("below the search's start" if stats["unexplained"] < UNEXPLAINED_FROM else
               f"not searched: the nominal torque varies {100 * stats['nominal_variation']:.2g} % of what is left")
        figures = f"{100 * stats['unexplained']:.3g} | ({why}) | | "
    ok = expected in (named, twin) if expected else not named
    named = f"{named} (as well: {twin})" if twin else named
    print(f"| {label} | {figures} | {named or 'nothing'} | {'yes' if ok else 'NO: expected ' + (expected or 'nothing')} |",
          flush=True)
    return ok


def _change(stats: dict) -> str:
    """The change a search's statistics hold, as "J2 -90°", "J2<->J3" (positions), "J2<->J3 with torques" or "J2
    reversed"."""
    shift, order = np.asarray(stats["shift"]), np.asarray(stats["order"])
    turned = [f"J{j + 1} {np.degrees(shift[j]):+.0f}°" for j in np.flatnonzero(shift)]
    swapped = [j for j in range(order.size) if order[j] != j]
    reversed_ = [f"J{j + 1} reversed" for j in np.flatnonzero(np.asarray(stats["direction"]) < 0)]
    gravity = "gravity [" + ", ".join(f"{x:g}" for x in stats["gravity"]) + "]"
    if turned or reversed_:
        return " ".join(turned + reversed_)
    if swapped:
        return f"J{swapped[0] + 1}<->J{swapped[1] + 1}" + (" with torques" if stats.get("channels") else "")
    return gravity


def _inverse(j: int, turn: str) -> str:
    """The change that undoes ``position_offset = turn`` on joint j (0-based)."""
    degrees = {"pi/2": -90, "-pi/2": 90, "pi": 180}[turn]
    return f"J{j + 1} {degrees:+d}°"


def main() -> int:
    import short_windows as sw

    from dynid.io.config.identification_config import load_identification_config

    folder = Path(tempfile.mkdtemp())
    configs = REPO / "configs"
    print("| case | left as logged, % | closest change | left so, % | ratio | named | as expected |")
    print("|---|---|---|---|---|---|---|")
    ok = []
    for name in ("ur10e", "tx40", "tx40-full", "kuka_kr300", "kuka_med7"):
        ok.append(_row(f"{name} as configured", load_identification_config(configs / f"{name}.toml"), ""))
    windows = {"ur10e": sw.WINDOWS, **sw.OTHER_WINDOWS}
    for key, more in sw.FRESH_WINDOWS.items():
        windows[key] = tuple(windows.get(key, ())) + tuple(more)
    for name, cut in windows.items():
        for window in cut:
            path, data_root = sw._window_config(name, window, folder)
            ok.append(_row(f"{name} {window[0]:g}-{window[1]:g}", load_identification_config(path, data_root=data_root), ""))
    robots = REPO / "src" / "dynid" / "model" / "robots"
    tx40 = re.sub(r'^position_offset = .*\n', "", (robots / "tx40.toml").read_text(), flags=re.M)
    (folder / "tx40.toml").write_text(tx40.replace('urdf = "tx40.urdf"', f'urdf = "{robots / "tx40.urdf"}"'))
    text = (configs / "tx40.toml").read_text().replace('robot = "tx40"', f'robot = "{folder / "tx40.toml"}"')
    ok.append(_row("tx40 without its offsets", _config(folder / "tx40-raw.toml", text, configs), "J2 -90° J3 +90°"))
    ur10e = (robots / "ur10e.toml").read_text().replace('urdf = "ur10e.urdf"', f'urdf = "{robots / "ur10e.urdf"}"')
    for j in (1, 2, 3):
        for turn in TURNS:
            parts = ur10e.split("[[joints]]")
            parts[j + 1] = f'\nposition_offset = "{turn}"' + parts[j + 1]
            robot = folder / f"ur10e-{j}-{turn.replace('/', '_')}.toml"
            robot.write_text("[[joints]]".join(parts))
            text = (configs / "ur10e.toml").read_text().replace('robot = "ur10e"', f'robot = "{robot}"')
            expected = "" if j == 3 or (j == 1 and turn == "pi") else _inverse(j, turn)
            ok.append(_row(f"ur10e J{j + 1} position_offset {turn}", _config(robot.with_suffix(".cfg.toml"), text, configs),
                           expected))
    med7_text = (configs / "kuka_med7.toml").read_text()

    def med7(gravity: str) -> str:
        return med7_text.replace('urdf = "urdf/med7dock.urdf"', f'urdf = "urdf/med7dock.urdf"\ngravity = {gravity}', 1)

    def ur10e_config(gravity: str) -> str:
        robot = folder / "ur10e-gravity.toml"
        robot.write_text(ur10e.replace("gravity = [0.0, 0.0, -9.81]", f"gravity = {gravity}"))
        return (configs / "ur10e.toml").read_text().replace('robot = "ur10e"', f'robot = "{robot}"')

    for j in (1, 2, 3, 5):
        for turn in TURNS:
            tables = "".join("\n[[robot.joints]]\n" + (f'position_offset = "{turn}"\n' if k == j else "") for k in range(7))
            text = med7_text.replace("\n[identification]", tables + "\n[identification]", 1)
            expected = "" if j == 5 or (j == 1 and turn == "pi") else _inverse(j, turn)
            ok.append(_row(f"kuka_med7 J{j + 1} position_offset {turn}",
                           _config(folder / f"med7-{j}-{turn.replace('/', '_')}.toml", text, configs), expected))
    columns = ["q_0", "q_1", "q_2", "q_3", "q_4", "q_5", "q_6"]
    for a, b in ((0, 1), (1, 2), (1, 3), (3, 5)):
        swapped = columns.copy()
        swapped[a], swapped[b] = swapped[b], swapped[a]
        text = med7_text.replace(", ".join(f'"{c}"' for c in columns), ", ".join(f'"{c}"' for c in swapped), 1)
        ok.append(_row(f"kuka_med7 J{a + 1} and J{b + 1} columns swapped", _config(folder / f"med7-swap-{a}{b}.toml", text, configs),
                       f"J{a + 1}<->J{b + 1}"))
    for a, b in ((0, 1), (0, 2), (1, 2), (1, 3), (3, 5)):  # a joint's positions and torque in another's place
        text = med7_text
        for kind in ("q", "tau"):
            names = [f"{kind}_{k}" for k in range(7)]
            swapped = names.copy()
            swapped[a], swapped[b] = swapped[b], swapped[a]
            text = text.replace(", ".join(f'"{c}"' for c in names), ", ".join(f'"{c}"' for c in swapped))
        ok.append(_row(f"kuka_med7 J{a + 1} and J{b + 1} positions and torques swapped",
                       _config(folder / f"med7-channels-{a}{b}.toml", text, configs), f"J{a + 1}<->J{b + 1} with torques"))
    positions = 'positions = { columns = ["q_0", "q_1", "q_2", "q_3", "q_4", "q_5", "q_6"] }'
    torques = 'torques = { columns = ["tau_0", "tau_1", "tau_2", "tau_3", "tau_4", "tau_5", "tau_6"], sign = -1'
    for j in (1, 2, 3, 5):  # a joint counted the other way round: its positions, or its positions and torque
        signs = "[" + ", ".join("-1" if k == j else "1" for k in range(7)) + "]"
        for both in (False, True):
            text = med7_text.replace(positions, positions[:-2] + f", sign = {signs} }}")
            if both:
                flipped = "[" + ", ".join("1" if k == j else "-1" for k in range(7)) + "]"
                text = text.replace(torques, torques.replace("sign = -1", f"sign = {flipped}"))
            expected = "" if j in (2, 5) else f"J{j + 1} reversed"  # J3: the LBR's links nearly symmetric about it
            ok.append(_row(f"kuka_med7 J{j + 1} positions{' and torque' if both else ''} reversed",
                           _config(folder / f"med7-rev-{j}-{both}.toml", text, configs), expected))
    for name, config in (("ur10e", ur10e_config), ("kuka_med7", med7)):
        for k, gravity in enumerate(("[9.81, 0.0, 0.0]", "[0.0, -9.81, 0.0]", "[0.0, 0.0, 9.81]")):
            # gravity reversed only flips the gravity torques: the sign check names that one
            expected = "" if k == 2 else "gravity [0, 0, -9.81]"
            ok.append(_row(f"{name} read with gravity = {gravity}", _config(folder / f"{name}-g{k}.toml", config(gravity),
                                                                             configs), expected))
    for factor, expected in ((10, "rate ×10"), (2, "rate ×2"), (0.5, "")):  # the Med7's 100 Hz read at another rate
        text = med7_text.replace("rate = 100.0", f"rate = {100.0 * factor}")
        ok.append(_row(f"kuka_med7 read at {100 * factor:g} Hz (its log: 100 Hz)",
                       _config(folder / f"med7-rate-{factor}.toml", text, configs), expected))
    tx40_text = (configs / "tx40.toml").read_text()
    ok.append(_row("tx40 read at 50 kHz (its log: 5 kHz)", _config(folder / "tx40-rate.toml", tx40_text.replace(
        "rate = 5000.0", "rate = 50000.0"), configs), "rate ×10"))
    print(f"\n{sum(ok)} of {len(ok)} cases as expected")
    return 0 if all(ok) else 1


def _config(path: Path, text: str, configs: Path):
    """A config written beside the others' data: its data_root made absolute."""
    from dynid.io.config.identification_config import load_identification_config

    text = re.sub(r'^data_root = "(.*)"', lambda m: f'data_root = "{(configs / m.group(1)).resolve()}"', text, flags=re.M)
    path.write_text(text)
    return load_identification_config(path)


if __name__ == "__main__":
    sys.exit(main())
