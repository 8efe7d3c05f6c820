"""Benchmark: excitation designs in a cell (issues "An excitation safe to run on the real robot" and "Every assurance
checked on what the user meets", item 1).

Four public arm descriptions of example-robot-data (UR5, Panda, Kinova Jaco 2, Unitree Z1; installed by the ``zoo``
extra) stand on a table (``[workspace] floor`` at the base's height) with one box within reach. For each arm and
seed, dynid designs the excitation twice: with the box and without it. Reported per arm:

- how many designs with the box bring a link's shape within the clearance of the box or of the table (or, a shape
  that starts within it, lower than it starts), or two shapes dynid keeps apart together, on a 1 kHz check of one
  period by an independent pass — target 0;
- the largest difference between the smallest distances dynid reports (its margins on the same 1 kHz samples) and
  that pass's, to the table and to the box — target 1 mm;
- how many collision-free designs cross the box (the box binds for those seeds);
- cond(W_base) with the box against without, on the seeds where the box does not bind and where it does;
- the design time with the box against without, measured in this run;
- how many designs with the box MuJoCo's own collision detection finds a shape within the clearance of the box or
  the table on, at 1 kHz (:func:`dynid.excitation.cell_replay.cell_contacts`, as ``dynid excite`` checks; target 0).

With ``--geometry collision`` (default) the links are the descriptions' own collision meshes (their convex hulls,
:mod:`dynid.excitation.link_geometry`), and the independent pass is Pinocchio's: its geometry model of the same URDF
placed by its own kinematics, each mesh's hull against the box by ``pinocchio.computeDistances`` and against the
table's plane by coal's distance to a half-space. With ``--geometry capsules`` the links are capsules about the joint
origins of dynid's estimated radius, and the pass is a brute force (points every millimetre along each link's
segment, the distance to the axis-aligned box by clipping, the segment's lowest end against the plane).

    python benchmarks/excite_cell.py --seeds 20
    python benchmarks/excite_cell.py --seeds 20 --geometry capsules
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent
sys.path.insert(0, str(REPO / "zoo"))

from zoo import ARMS, arm_urdf, robots_folder  # noqa: E402

from dynid.dynamics.kinematics import forward_kinematics  # noqa: E402
from dynid.exceptions import ConfigError  # noqa: E402
from dynid.excitation.cell_replay import cell_contacts  # noqa: E402
from dynid.excitation.constraints import Workspace  # noqa: E402
from dynid.excitation.design import ExcitationProblem, InfeasibleDesignError, design_excitation  # noqa: E402
from dynid.excitation.obstacles import Obstacle  # noqa: E402
from dynid.model.description import load_robot  # noqa: E402
from dynid.runtime.threads import with_single_blas_thread  # noqa: E402

CELL_ARMS = ("UR5", "Panda", "Kinova Jaco 2", "Unitree Z1")
CLEARANCE = 0.05
HARMONICS, FREQUENCY, GRID, STARTS, MAXITER = 3, 0.1, 60, 2, 100


def _arm(name: str, folder: Path, meshes: bool = False):
    file, keep = ARMS[name]
    path = folder / f"{name.replace(' ', '_')}.urdf"
    text = (robots_folder() / file).read_text(encoding="utf-8")
    path.write_text(_with_collisions(text, keep) if meshes else arm_urdf(text, keep))
    robot = load_robot(str(path))
    lim = robot.limits
    from dataclasses import replace
    lo, hi = np.maximum(lim.q_min, -np.pi), np.minimum(lim.q_max, np.pi)
    # a first, cautious run: half the rated speed, 3 rad/s², the description's torques
    return replace(robot, limits=replace(lim, q_min=lo, q_max=hi, dq_max=np.minimum(0.5 * lim.dq_max, 1.5),
                                         ddq_max=np.full(robot.n_dof, 3.0)))


def _with_collisions(text: str, keep: str) -> str:
    """The URDF with every movable joint but the arm's made fixed, its collision meshes kept by absolute path."""
    import re
    import xml.etree.ElementTree as ET

    root = ET.fromstring(text.replace("package://example-robot-data/robots/", f"{robots_folder()}/"))
    for link in root.iter("link"):
        for child in [c for c in link if c.tag == "visual"]:
            link.remove(child)
    for joint in root.iter("joint"):
        if joint.get("type") in ("revolute", "continuous", "prismatic") and not re.search(keep, joint.get("name", "")):
            joint.set("type", "fixed")
            for child in [c for c in joint if c.tag in ("mimic", "limit", "dynamics", "axis", "safety_controller")]:
                joint.remove(child)
    for gazebo in [c for c in root if c.tag in ("gazebo", "transmission", "ros2_control")]:
        root.remove(gazebo)
    return ET.tostring(root, encoding="unicode")


def _pinocchio_check(path: Path, robot, q: np.ndarray, ws: Workspace) -> tuple[float, float, float]:
    """By Pinocchio alone (its geometry model of the URDF, its kinematics, the meshes' hulls) and coal: the smallest
    distance beyond the clearance from a moving shape to the box, the smallest distance between the shape pairs dynid
    keeps apart, and the smallest height above the table beyond what each moving shape keeps (the clearance, or a
    millimetre below its start height where it starts within it; shapes whose height never changes left out)."""
    import coal
    import pinocchio as pin

    from dynid.excitation.link_geometry import self_pairs

    model = pin.buildModelFromUrdf(str(path))
    geom = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION)
    for obj in geom.geometryObjects:
        if isinstance(obj.geometry, coal.BVHModelBase):
            obj.geometry.buildConvexHull(True, "Qt")
            obj.geometry = obj.geometry.convex
    box = ws.obstacles[0]
    placement = pin.SE3(pin.rpy.rpyToMatrix(*box.rpy), box.position)
    bid = geom.addGeometryObject(pin.GeometryObject("box", 0, placement, coal.Box(*box.size)))
    moving = [g for g, obj in enumerate(geom.geometryObjects) if obj.parentJoint > 0]
    for g in moving:
        geom.addCollisionPair(pin.CollisionPair(g, bid))
    n_box = len(moving)
    names = ws.geometry.names
    for g, h in self_pairs(robot, ws.geometry):
        geom.addCollisionPair(pin.CollisionPair(geom.getGeometryId(names[g]), geom.getGeometryId(names[h])))
    data, gdata = model.createData(), pin.GeometryData(geom)
    ids = [model.getJointId(j.name) for j in robot.joints]
    plane = coal.Halfspace(np.array([0.0, 0.0, 1.0]), ws.floor)

    def configuration(angles):
        qn = pin.neutral(model)
        for j, jid in enumerate(ids):
            iq = model.joints[jid].idx_q
            if model.joints[jid].nq == 2:  # continuous: (cos, sin)
                qn[iq:iq + 2] = np.cos(angles[j]), np.sin(angles[j])
            else:
                qn[iq] = angles[j]
        return qn

    def heights(angles) -> np.ndarray:
        pin.updateGeometryPlacements(model, data, geom, gdata, configuration(angles))
        out = np.empty(len(moving))
        for c, g in enumerate(moving):
            result, placed = coal.DistanceResult(), gdata.oMg[g]
            coal.distance(geom.geometryObjects[g].geometry, coal.Transform3s(placed.rotation, placed.translation), plane,
                          coal.Transform3s(), coal.DistanceRequest(), result)
            out[c] = result.min_distance
        return out

    start = heights(q[0])
    rng = np.random.default_rng(0)
    lo, hi = np.maximum(robot.limits.q_min, -np.pi), np.minimum(robot.limits.q_max, np.pi)
    sampled = np.array([heights(lo + rng.random(robot.n_dof) * (hi - lo)) for _ in range(24)])
    keep = np.ptp(sampled, axis=0) > 1e-6  # a housing turning about a vertical axis never moves down
    need = np.minimum(ws.clearance, start - 1e-3)
    best, apart, floor = np.inf, np.inf, np.inf
    for n in range(q.shape[0]):
        pin.computeDistances(model, data, geom, gdata, configuration(q[n]))
        d = [r.min_distance for r in gdata.distanceResults]
        best = min(best, min(d[:n_box]))
        apart = min(apart, min(d[n_box:], default=np.inf))
        floor = min(floor, float((heights(q[n]) - need)[keep].min(initial=np.inf)))
    return best - ws.clearance, apart, floor


def _start(robot) -> np.ndarray:
    """A start pose held up off the table: of 4000 random poses in the middle half of the joints' ranges (seed 0), the
    one whose lowest moving joint origin and tool point are highest."""
    lo, hi = robot.limits.q_min, robot.limits.q_max
    q = 0.5 * (lo + hi) + (np.random.default_rng(0).random((4000, robot.n_dof)) - 0.5) * 0.5 * (hi - lo)
    rots, orig = forward_kinematics(robot, q)
    tool = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    z = np.concatenate([orig[:, :, 2], tool[:, None, 2]], axis=1)
    z = z[:, np.ptp(z, axis=0) > 1e-6]
    return q[int(np.argmax(z.min(axis=1)))]


def _cell(robot, geometry=None) -> Workspace:
    """A table under the base (where its collision shapes end, or at the base frame's origin) and a box of a fifth of the
    reach, half the reach from the base, a quarter of the reach above the table, off the start."""
    reach = robot.reach
    q0 = _start(robot)
    base_z = 0.0  # the table: the base frame's origin, or the bottom of the base's own collision shapes
    if geometry is not None and np.any(geometry.link < 0):
        from dynid.excitation.floor import lowest_points

        base_z = float(lowest_points(robot, np.zeros((1, robot.n_dof)), geometry, np.flatnonzero(geometry.link < 0))[..., 2].min())
    for angle in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        centre = np.array([0.5 * reach * np.cos(angle), 0.5 * reach * np.sin(angle), base_z + 0.25 * reach])
        box = Obstacle("box", np.full(3, 0.2 * reach), centre, name="box")
        ws = Workspace(floor=base_z - 1e-3, clearance=CLEARANCE, obstacles=(box,), geometry=geometry)
        try:
            ExcitationProblem(robot, 2 * np.pi * FREQUENCY, HARMONICS, offsets=q0, workspace=ws, rest=True, grid_points=GRID)
            return ws
        except ConfigError as exc:  # the start pose touches it: turn it about the base
            print(f"  {robot.name}: {exc}")
            continue
    raise SystemExit(f"{robot.name}: no place for the box off the start pose")


def _brute_force(robot, q, ws: Workspace) -> tuple[float, float]:
    """Smallest capsule-to-box distance beyond the clearance and smallest capsule height above the floor beyond what
    it keeps, independently (the capsules of dynid's estimated radius about each link's segment)."""
    r = ws.capsule_radius(robot)
    rots, orig = forward_kinematics(robot, q)
    flange = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    ends = np.concatenate([orig[:, 1:], flange[:, None]], axis=1)
    length = np.linalg.norm(ends - orig, axis=-1).max()
    s = np.linspace(0.0, 1.0, max(2, int(length / 1e-3)))
    box = ws.obstacles[0]
    best = np.inf
    for k in range(robot.n_dof):
        pts = orig[:, k, None] + s[None, :, None] * (ends[:, k] - orig[:, k])[:, None]
        gap = np.maximum(np.abs(pts - box.position) - 0.5 * box.size, 0.0)
        best = min(best, float(np.linalg.norm(gap, axis=-1).min()) - r - CLEARANCE)
    low = np.minimum(orig[..., 2], ends[..., 2]) - r - ws.floor
    need = np.minimum(CLEARANCE, low[0] - 1e-3)
    moving = np.ptp(low, axis=0) > 1e-6
    return best, float((low - need)[:, moving].min())


def _reported(robot, t, q, ws: Workspace) -> tuple[float, float]:
    """The smallest distances dynid reports on the same samples: to the box beyond the clearance, and to the floor
    beyond what each shape keeps."""
    from dynid.excitation.constraints import floor_margins, obstacle_margins

    [floor] = floor_margins(robot, t, q, ws, q[0])
    return min(m.worst for m in obstacle_margins(robot, t, q, ws)), floor.margin


def _design(robot, ws: Workspace, seed: int):
    q0 = _start(robot)
    prob = ExcitationProblem(robot, 2 * np.pi * FREQUENCY, HARMONICS, offsets=q0, workspace=ws, rest=True, grid_points=GRID)
    t0 = time.perf_counter()
    design = design_excitation(prob, n_starts=STARTS, rng=seed, maxiter=MAXITER)
    return design, time.perf_counter() - t0


@with_single_blas_thread
def run_arm(name: str, seeds: int, folder: Path, meshes: bool = False, first: int = 0) -> dict:
    robot = _arm(name, folder, meshes)
    path = folder / f"{name.replace(' ', '_')}.urdf"
    geometry = None
    if meshes:
        from dynid.excitation.link_geometry import link_geometry_from_urdf

        geometry = link_geometry_from_urdf(robot, path)
    ws = _cell(robot, geometry)
    free_ws = Workspace(floor=ws.floor, clearance=CLEARANCE, geometry=geometry)
    rows = []
    for seed in range(first, first + seeds):
        try:
            with_box, t_box = _design(robot, ws, seed)
            without, t_free = _design(robot, free_ws, seed)
        except InfeasibleDesignError as exc:  # refused, not written as if safe: counted apart
            rows.append(dict(seed=seed, refused=str(exc)))
            print(f"  {name} seed {seed}: refused: {exc}", flush=True)
            continue
        t = np.arange(int(round(1000 / FREQUENCY))) / 1000.0  # one period at 1 kHz
        q_box, q_free = with_box.trajectory.evaluate(t)[0], without.trajectory.evaluate(t)[0]
        if meshes:
            box_d, apart, floor_d = _pinocchio_check(path, robot, q_box, ws)
            free_d = _pinocchio_check(path, robot, q_free, ws)[0]
        else:
            (box_d, floor_d), (free_d, _), apart = _brute_force(robot, q_box, ws), _brute_force(robot, q_free, ws), np.inf
        said_box, said_floor = _reported(robot, t, q_box, ws)
        agree = max(abs(said_box - box_d), abs(said_floor - floor_d))
        contacts = cell_contacts(robot, t, q_box, ws)  # MuJoCo's own collision detection, where it is installed
        touching = None if contacts is None else contacts.touching
        rows.append(dict(seed=seed, refused=None, box=box_d, apart=apart, floor=floor_d, agree=agree, crossed=free_d < 0,
                         cond=with_box.cond,
                         cond_free=without.cond, time=t_box, time_free=t_free, mujoco=touching))
        print(f"  {name} seed {seed}: box {box_d:+.4f} m, floor {floor_d:+.4f} m, shapes apart {apart:+.4f} m, dynid's "
              f"figures within {agree * 1e3:.3f} mm, collision-free design "
              f"{free_d:+.4f} m; cond {with_box.cond:.1f} / {without.cond:.1f}; {t_box:.1f} / {t_free:.1f} s", flush=True)
    return dict(name=name, n=robot.n_dof, rows=rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--arms", default=",".join(CELL_ARMS))
    parser.add_argument("--geometry", choices=("capsules", "collision"), default="collision")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        results = [run_arm(name, args.seeds, Path(tmp), args.geometry == "collision", args.first_seed) for name in args.arms.split(",")]
    print("\n| arm | joints | seeds | within the box's or the table's clearance, or shapes touching (1 kHz) | dynid's "
          "smallest distances against the pass, largest difference | MuJoCo: designs with a "
          "contact within the clearance (1 kHz) | free design crosses the box | cond ratio, box does not bind | cond "
          "ratio, box binds | time ratio (median) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        refused = sum(x["refused"] is not None for x in r["rows"])
        rows = [x for x in r["rows"] if x["refused"] is None]
        bad = sum(x["box"] < -1e-6 or x["floor"] < -1e-6 or x["apart"] < -1e-6 for x in rows)
        free = [x["cond"] / x["cond_free"] for x in rows if not x["crossed"]]
        bind = [x["cond"] / x["cond_free"] for x in rows if x["crossed"]]
        span = lambda v: f"{min(v):.2f}-{max(v):.2f}" if v else "—"  # noqa: E731
        ratio = np.median([x["time"] / x["time_free"] for x in rows])
        mujoco = [x["mujoco"] for x in rows if x["mujoco"] is not None]
        seen = f"{sum(m > 0 for m in mujoco)} of {len(mujoco)}" if mujoco else "not installed"
        agree = max((x["agree"] for x in rows), default=float("nan")) * 1e3
        print(f"| {r['name']} | {r['n']} | {len(rows)} (+{refused} refused) | {bad} | {agree:.3f} mm | {seen} | {sum(x['crossed'] for x in rows)} | {span(free)} | "
              f"{span(bind)} | {ratio:.2f} |")


if __name__ == "__main__":
    main()
