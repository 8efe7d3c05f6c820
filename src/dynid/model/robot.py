"""What a robot is: an immutable serial chain of revolute and prismatic joints with its parameters.

Every joint ``j`` has a fixed placement ``(R_j, p_j)`` of its frame in the frame of link ``j-1``
(the base for ``j = 0``) and a unit axis in its own frame; link ``j``'s frame is the joint frame after the
rotation by ``q_j`` about the axis (revolute) or the translation by ``q_j`` along it (prismatic). Modified DH (Khalil/Craig, the paper's Table 1), standard DH
and URDF chains all reduce to this form (see :mod:`dynid.model.dh` and :mod:`dynid.model.urdf`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .._util.reprs import short_repr
from ..conventions import DEFAULT_DRIVE_TERMS, INERTIAL_TERMS, parameter_name
from ..exceptions import ConfigError
from ..friction import DEFAULT_STRIBECK_VELOCITY, Velocities, check_terms
from .spatial import is_physically_consistent, nearest_consistent, rot_axis, transform_inertial
from .transmission import Transmission


@short_repr
@dataclass(frozen=True)
class Joint:
    """One joint: placement in the parent link frame and axis (of rotation, or of translation if prismatic).

    Attributes
    ----------
    name : str
    rotation : (3, 3) array
        Orientation of the joint frame in the parent link frame (``parent_R_joint``) at ``q = 0``.
    translation : (3,) array
        Origin of the joint frame in the parent link frame [m].
    axis : (3,) array
        Unit axis in the joint frame (``(0, 0, 1)`` for DH chains).
    prismatic : bool
        The joint slides along its axis (position [m], force [N]) instead of turning about it.
    parent : int or None
        The index of the joint whose link carries this joint (-1: the base), for a robot with branches (two arms on a
        torso); ``None``: the joint before it in the robot's order (a serial chain).
    mimic : tuple of (int, float, float) or None
        ``(k, multiplier, offset)`` for a joint that follows joint ``k`` (a URDF's ``<mimic>``: a parallelogram's
        passive joint, a coupled finger): its position is ``multiplier · q_k + offset``, and the torque (or force)
        it needs is supplied through joint ``k``, whose row of the regressor holds ``multiplier`` times this joint's
        (virtual work); None: an independent joint.
    """

    name: str
    rotation: np.ndarray
    translation: np.ndarray
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    prismatic: bool = False
    parent: int | None = None
    mimic: tuple[int, float, float] | None = None

    def placement(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The frame of the joint's link in its parent's, at positions ``q``.

        Parameters
        ----------
        q : (N,) array
            Joint position [rad], or [m] if prismatic.

        Returns
        -------
        rotations : (N, 3, 3) array
        translations : (N, 3) array [m]
        """
        q = np.asarray(q, dtype=float)
        if self.prismatic:
            return (np.broadcast_to(self.rotation, (q.size, 3, 3)).copy(),
                    self.translation + q[:, None] * (self.rotation @ self.axis))
        return self.rotation @ rot_axis(self.axis, q), np.broadcast_to(self.translation, (q.size, 3)).copy()


@short_repr
@dataclass(frozen=True)
class Limits:
    """Joint limits; unknown limits are ``inf``.

    Attributes
    ----------
    q_min, q_max : (n_dof,) arrays [rad]
        Position limits.
    dq_max : (n_dof,) array [rad/s]
        |velocity| limit.
    ddq_max : (n_dof,) array [rad/s²]
        |acceleration| limit.
    tau_max : (n_dof,) array [N·m]
        |torque| limit.
    """

    q_min: np.ndarray
    q_max: np.ndarray
    dq_max: np.ndarray
    ddq_max: np.ndarray
    tau_max: np.ndarray

    def subset(self, k: int) -> Limits:
        """The limits of the first joints.

        Parameters
        ----------
        k : int
            Number of joints kept.

        Returns
        -------
        Limits
        """
        return Limits(*(getattr(self, f)[:k].copy() for f in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max")))

    def position_span(self) -> tuple[np.ndarray, np.ndarray]:
        """The position limits with ±π where a joint has none (a continuous joint's one turn).

        Returns
        -------
        lo, hi : (n_dof,) arrays [rad]
        """
        return (np.where(np.isfinite(self.q_min), self.q_min, -np.pi),
                np.where(np.isfinite(self.q_max), self.q_max, np.pi))

    def random_positions(self, n: int, rng, span: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """``n`` poses drawn uniformly within :meth:`position_span`.

        Parameters
        ----------
        n : int
        rng : Generator or int seed
        span : (lo, hi) of (n_dof,) arrays, optional
            Another span to draw within (:meth:`Robot.coupled_span`).

        Returns
        -------
        (n, n_dof) array [rad]
        """
        lo, hi = self.position_span() if span is None else span
        return lo + np.random.default_rng(rng).random((n, lo.size)) * (hi - lo)


@short_repr
@dataclass(frozen=True)
class Robot:
    """A serial robot arm with revolute and prismatic joints (immutable).

    Attributes
    ----------
    name : str
    joints : tuple of Joint
    gravity : (3,) array
        Gravity acceleration in the base frame [m/s²], e.g. ``(0, 0, -9.81)``.
    inertial : (n_dof, 10) array
        Standard inertial parameters of each link (eq. 5 order, about the link frame origin): the
        nominal values, used as simulation truth by the paper experiment.
    drive_terms : tuple of str
        Drive/friction terms identified for every joint, a subset of ``DRIVE_TERMS`` (eq. 3).
    drive : (n_dof, len(drive_terms)) array
        Nominal values of those terms.
    drive_gains : (n_dof,) array
        Drive gains ``K`` of eq. 16, joint torque per motor current [N·m/A].
    limits : Limits
    tool_rotation, tool_translation : arrays
        Tool (flange) frame in the last link frame.
    notes : str
        Provenance of the numbers (e.g. which values are assumed).
    transmission : Transmission
        Gear ratios, coupling and encoder zeros (default: identity, no coupling). Coupled motors add
        parameters after the joint blocks (``Iam6``, ``fvm6``, ``fcm6``).
    drive_mask : (n_dof, len(drive_terms)) bool array
        Which drive terms each joint has (default all); a joint without a term has a zero column,
        so the term drops out of the base parameters.
    nominal_problems : tuple of str
        Physical-consistency rules the nominal inertial parameters break (one line each, naming the
        link and the rule). Identification by least squares does not use the nominal values, so such a
        description is accepted; :meth:`require_physical_nominal` refuses it where they are used.
    coulomb_velocity : (n_dof,) array [rad/s]
        Smoothing velocity ``v_s`` of each joint's Coulomb term: its column is ``tanh(dq/v_s)`` (still
        linear in ``fc``), or ``sign(dq)`` where ``v_s = 0`` (default). See :mod:`dynid.friction`.
    stribeck_velocity : (n_dof,) array [rad/s]
        Stribeck velocity of the ``fst`` term (default :data:`dynid.friction.DEFAULT_STRIBECK_VELOCITY`).
    nominal_notes : tuple of str
        What the description states that dynid does not take as nominal values (one line each): a URDF's
        ``<dynamics>`` damping and friction.
    held : tuple of str
        Joints of the robot's URDF held fixed, not identified (a gripper's fingers): their links count with the link
        they are held to, as a fixed joint's do (:func:`dynid.model.urdf.joints_from_urdf`).
    prior_sigma : tuple of (str, float)
        ``(parameter name, σ)`` of the drive terms whose nominal value the description states with an uncertainty
        (``Ia = { value = 0.3, sigma = 0.05 }``): the estimates that pull toward the nominal values pull these with a
        Gaussian prior of that σ (:meth:`prior_weights`).
    """

    name: str
    joints: tuple[Joint, ...]
    gravity: np.ndarray
    inertial: np.ndarray
    drive_terms: tuple[str, ...]
    drive: np.ndarray
    drive_gains: np.ndarray
    limits: Limits
    tool_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    tool_translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    notes: str = ""
    # given or None; __post_init__ fills in the defaults, so after construction they are never None
    transmission: Transmission = None  # type: ignore[assignment]
    drive_mask: np.ndarray = None  # type: ignore[assignment]
    coulomb_velocity: np.ndarray = None  # type: ignore[assignment]
    nominal_problems: tuple[str, ...] = ()
    held: tuple[str, ...] = ()
    nominal_notes: tuple[str, ...] = ()
    stribeck_velocity: np.ndarray = None  # type: ignore[assignment]
    prior_sigma: tuple[tuple[str, float], ...] = ()

    @property
    def friction_velocities(self) -> Velocities:
        """The per-joint velocities the friction columns use (:mod:`dynid.friction`)."""
        return Velocities(self.coulomb_velocity, self.stribeck_velocity)

    def prior_sigmas(self) -> np.ndarray:
        """Each standard parameter's prior standard deviation where the description states one
        (:attr:`prior_sigma`), NaN elsewhere.

        Returns
        -------
        (n_params,) ndarray
            :attr:`parameter_names` order.
        """
        names = list(self.parameter_names)
        out = np.full(len(names), np.nan)
        for name, sigma in self.prior_sigma:
            if name in names:  # a term the robot no longer has (a joint torque sensor's Ia) is dropped with it
                out[names.index(name)] = sigma
        return out

    def physical_prior(self) -> tuple[np.ndarray, tuple[str, ...]]:
        """The nominal standard parameters with each physically impossible link replaced by its nearest consistent
        one (:func:`dynid.model.spatial.nearest_consistent`), as the prior of a physically consistent estimate.

        Returns
        -------
        phi : (n_params,) ndarray
            :attr:`parameter_names` order.
        notes : tuple of str
            One line per link replaced, naming it and the rule its nominal values break.
        """
        bad = [j for j in range(self.n_dof) if not is_physically_consistent(self.inertial[j])]
        if not bad:
            return self.standard_parameters(), ()
        fixed = self.inertial.copy()
        notes = []
        for j in bad:
            fixed[j] = nearest_consistent(self.inertial[j])
            said = [p for p in self.nominal_problems if f"link {j + 1} " in p] or [f"link {j + 1}: nominal inertial parameters"]
            notes.append(f"{said[0]}: the physically consistent estimate's prior and the nominal candidate take the "
                         "nearest consistent link (its pseudo-inertia's negative eigenvalues raised to zero)")
        return replace(self, inertial=fixed).standard_parameters(), tuple(notes)

    def require_physical_nominal(self, use: str) -> None:
        """Refuse nominal inertial parameters that are those of no real mass distribution.

        Degenerate but realisable links (a massless link, a point mass, a thin rod) pass: they only have a warning in
        :attr:`nominal_problems`.

        Parameters
        ----------
        use : str
            What the nominal parameters are needed for (e.g. "the simulation truth"), named in the error.

        Raises
        ------
        ConfigError
            Naming the link and the rule, when a pseudo-inertia is not positive semidefinite.
        """
        bad = [j for j in range(self.n_dof) if not is_physically_consistent(self.inertial[j])]
        if bad:
            lines = [p for p in self.nominal_problems if f"link {bad[0] + 1} " in p] or [f"link {bad[0] + 1}: nominal inertial parameters"]
            more = f" (and {len(bad) - 1} more link(s))" if len(bad) > 1 else ""
            raise ConfigError(f"{lines[0]}{more}: {use} needs physically consistent nominal values")

    def __post_init__(self) -> None:
        n = len(self.joints)
        vs = np.zeros(n) if self.coulomb_velocity is None else np.array(self.coulomb_velocity, dtype=float).reshape(-1)
        if vs.shape != (n,) or not np.all(np.isfinite(vs)) or np.any(vs < 0):
            raise ConfigError(f"robot {self.name!r}: coulomb_velocity: expected {n} non-negative velocities (rad/s), got {self.coulomb_velocity!r}")
        object.__setattr__(self, "coulomb_velocity", vs)
        vst = np.full(n, DEFAULT_STRIBECK_VELOCITY) if self.stribeck_velocity is None else np.array(self.stribeck_velocity, dtype=float).reshape(-1)
        if vst.shape != (n,) or not np.all(np.isfinite(vst)) or np.any(vst <= 0):
            raise ConfigError(f"robot {self.name!r}: stribeck_velocity: expected {n} positive velocities (rad/s), got {self.stribeck_velocity!r}")
        object.__setattr__(self, "stribeck_velocity", vst)
        if self.transmission is None:
            object.__setattr__(self, "transmission", Transmission.identity(n))
        if self.transmission.n_dof != n:
            raise ConfigError(f"robot {self.name!r}: transmission is for {self.transmission.n_dof} joints, the chain has {n}")
        mask = np.ones((n, len(self.drive_terms)), dtype=bool) if self.drive_mask is None else np.array(self.drive_mask, dtype=bool)
        if mask.shape != (n, len(self.drive_terms)):
            raise ConfigError(f"robot {self.name!r}: expected a drive mask of shape ({n}, {len(self.drive_terms)}), got {mask.shape}")
        object.__setattr__(self, "drive_mask", mask)
        if n == 0:
            raise ConfigError(f"robot {self.name!r}: expected at least one joint, got none")
        for j, jt in enumerate(self.joints):
            if jt.mimic is not None:
                k, multiplier, _ = jt.mimic
                followed = repr(self.joints[k].name) if 0 <= k < n else str(k)
                if not (0 <= k < n and k != j and self.joints[k].mimic is None and np.isfinite(jt.mimic[1:]).all()
                        and multiplier != 0):
                    raise ConfigError(f"robot {self.name!r}: joint {jt.name!r} mimics joint {followed} (multiplier "
                                      f"{multiplier:g}, offset {jt.mimic[2]:g}): expected another joint of the robot that "
                                      "mimics none, a finite non-zero multiplier and a finite offset")
                mask[j] = False  # a joint that follows another has no drive of its own: its friction is its master's
            if jt.parent is not None and not -1 <= jt.parent < j:
                raise ConfigError(f"robot {self.name!r}: joint {jt.name!r} is carried by joint {jt.parent}: expected a "
                                  f"joint before it (0 to {j - 1}) or -1, the base (joints in depth-first order)")
        if self.inertial.shape != (n, 10):
            raise ConfigError(f"robot {self.name!r}: expected inertial parameters of shape ({n}, 10), got {self.inertial.shape}")
        try:
            check_terms(self.drive_terms, f"robot {self.name!r}")
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
        if self.drive.shape != (n, len(self.drive_terms)):
            raise ConfigError(f"robot {self.name!r}: expected drive parameters of shape ({n}, {len(self.drive_terms)}), got {self.drive.shape}")
        if np.any(self.drive[~mask] != 0):
            raise ConfigError(f"robot {self.name!r}: a drive term a joint does not have must have the value 0")
        gains = np.asarray(self.drive_gains, dtype=float)
        if gains.shape != (n,) or not np.all(np.isfinite(gains)) or np.any(gains == 0):  # a robot built by the API
            raise ConfigError(f"robot {self.name!r}: drive_gains: expected {n} finite, non-zero gains (N·m per A), "
                              f"got {np.asarray(self.drive_gains).tolist()}", field="drive_gains")
        for a in (self.gravity, self.inertial, self.drive, self.drive_gains, self.tool_rotation, self.tool_translation, mask, vs, vst):
            a.setflags(write=False)

    @property
    def n_dof(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def parents(self) -> np.ndarray:
        """(n_dof,) int: the joint whose link carries each joint (-1: the base); ``j - 1`` along a serial chain, and
        each joint's :attr:`Joint.parent` on a robot with branches (a tree, joints in depth-first order)."""
        return np.array([j - 1 if jt.parent is None else jt.parent for j, jt in enumerate(self.joints)], dtype=np.int64)

    @property
    def carries(self) -> np.ndarray:
        """(n_dof, n_dof) bool: ``carries[j, k]``, whether joint ``j`` moves link ``k`` (``j`` is ``k`` or a joint on
        the way from the base to it): ``j <= k`` along a serial chain; on a robot with branches, one arm's joints do
        not move the other arm."""
        parents = self.parents
        out = np.zeros((self.n_dof, self.n_dof), dtype=bool)
        for k in range(self.n_dof):
            j = k
            while j >= 0:
                out[j, k] = True
                j = parents[j]
        return out

    @property
    def is_tree(self) -> bool:
        """Whether the robot has branches (two arms on a torso): a joint not carried by the joint before it."""
        return bool(np.any(self.parents != np.arange(self.n_dof) - 1))

    def flange(self, *, link: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The frame a tool or payload on link ``link`` (0-based; default the last) is given in, in that link's frame:
        the tool frame on the last link, the link's own frame on another (a robot with branches states no tool there).

        Parameters
        ----------
        link : int, optional

        Returns
        -------
        rotation : (3, 3) array
        translation : (3,) array [m]
        """
        if link is None or link in (-1, self.n_dof - 1):
            return np.asarray(self.tool_rotation, dtype=float), np.asarray(self.tool_translation, dtype=float)
        return np.eye(3), np.zeros(3)

    @property
    def tips(self) -> np.ndarray:
        """(n_tips,) int: the joints whose link carries no other joint (each branch's hand), in the robot's order; the
        last joint alone on a serial chain (the tool's, always the last of them)."""
        return np.setdiff1d(np.arange(self.n_dof), self.parents)

    @property
    def prismatic(self) -> np.ndarray:
        """(n_dof,) bool: which joints slide (position [m], force [N]) rather than turn."""
        return np.array([j.prismatic for j in self.joints], dtype=bool)

    @property
    def followers(self) -> tuple[int, ...]:
        """The joints that follow another (:attr:`Joint.mimic`: a URDF's ``<mimic>``), in the robot's order; empty on
        most robots."""
        return tuple(j for j, jt in enumerate(self.joints) if jt.mimic is not None)

    @property
    def independent(self) -> np.ndarray:
        """(n_dof,) bool: the joints that follow none: the robot's coordinates, whose columns its logs hold."""
        return np.array([jt.mimic is None for jt in self.joints], dtype=bool)

    def coupled(self, q, dq=None, ddq=None) -> tuple:
        """States with each following joint's column taken from the joint it follows (:attr:`Joint.mimic`): position
        ``multiplier · q_k + offset``, velocity and acceleration ``multiplier`` times joint ``k``'s.

        Parameters
        ----------
        q : (N, n_dof) array [rad or m]
        dq, ddq : (N, n_dof) arrays, optional
            [rad/s or m/s], [rad/s² or m/s²].

        Returns
        -------
        tuple of (N, n_dof) arrays (None where not given)
            Copies where the robot has following joints, the arrays given otherwise.
        """
        if not self.followers:
            return q, dq, ddq
        out = []
        for x, offset in ((q, True), (dq, False), (ddq, False)):
            if x is not None:
                x = np.array(x, dtype=float)
                for j in self.followers:
                    k, multiplier, shift = self.joints[j].mimic  # type: ignore[misc]
                    x[..., j] = multiplier * x[..., k] + (shift if offset else 0.0)
            out.append(x)
        return tuple(out)

    def widened(self, x) -> np.ndarray:
        """Columns of the robot's coordinates (a log's: none of a joint that follows another) as one per joint, a
        follower's 0 (:meth:`coupled` fills its motion); an array with a column per joint, or on a robot without
        followers, as given.

        Parameters
        ----------
        x : (..., n_coordinates) array

        Returns
        -------
        (..., n_dof) array
        """
        x = np.asarray(x, dtype=float)
        if not self.followers or x.shape[-1] != int(self.independent.sum()):
            return x
        wide = np.zeros(x.shape[:-1] + (self.n_dof,))
        wide[..., self.independent] = x
        return wide

    def coupled_span(self) -> tuple[np.ndarray, np.ndarray]:
        """The joints' position spans (:meth:`Limits.position_span`), a joint that others follow narrowed to where they
        stay within theirs (where its coupling can: out of range, a simulator's joint limit would act).

        Returns
        -------
        lo, hi : (n_dof,) arrays [rad or m]
        """
        lo, hi = self.limits.position_span()
        for j in self.followers:
            k, multiplier, offset = self.joints[j].mimic  # type: ignore[misc]
            a, b = sorted(((lo[j] - offset) / multiplier, (hi[j] - offset) / multiplier))
            if max(lo[k], a) < min(hi[k], b):
                lo[k], hi[k] = max(lo[k], a), min(hi[k], b)
        return lo, hi

    def followers_said(self, *, columns: str = "no column of theirs in a log") -> str:
        """One line on the joints that follow another (``""`` on a robot without): which, how, and where their torque
        goes, for the outputs that list every joint.

        Parameters
        ----------
        columns : str
            What the line says of their columns (a log's; excitation.csv's).

        Returns
        -------
        str
        """
        said = []
        for j in self.followers:
            k, multiplier, offset = self.joints[j].mimic  # type: ignore[misc]
            unit = "m" if self.joints[j].prismatic else "rad"
            said.append(f"J{j + 1} ({self.joints[j].name}) follows J{k + 1} ({self.joints[k].name}): q{j + 1} = "
                        f"{multiplier:g}·q{k + 1} + {offset:g} {unit}")
        if not said:
            return ""
        return ("; ".join(said) + f" (<mimic>): {columns}, no drive of their own; the torque they need is supplied by the "
                "joint they follow and counted in its row")

    def fold(self, rows: np.ndarray) -> np.ndarray:
        """Rows of per-joint torques (N, n_dof) or of the regressor (N, n_dof, p), each following joint's row added to
        the row of the joint it follows times its multiplier (virtual work: that joint's drive supplies it) and then
        zeroed, in place.

        Parameters
        ----------
        rows : (N, n_dof) or (N, n_dof, p) array

        Returns
        -------
        The same array.
        """
        for j in self.followers:
            k, multiplier, _ = self.joints[j].mimic  # type: ignore[misc]
            rows[:, k] += multiplier * rows[:, j]
            rows[:, j] = 0.0
        return rows

    @property
    def reach(self) -> float:
        """[m] The sum of the joints' offsets, the flange's and each prismatic joint's stroke (its farther limit): no point
        of the arm's skeleton is farther than this from the first joint's origin (a prismatic joint without limits
        adds nothing); on a robot with branches, that sum along the longest way from the base to a branch's tip."""
        stroke = np.where(self.prismatic, np.maximum(np.abs(self.limits.q_min), np.abs(self.limits.q_max)), 0.0)
        if not self.is_tree:
            return (sum(float(np.linalg.norm(j.translation)) for j in self.joints) + float(np.linalg.norm(self.tool_translation))
                    + float(np.sum(np.where(np.isfinite(stroke), stroke, 0.0))))
        # a robot with branches: the longest way from the base to a branch's tip (the tool on the last joint's)
        step = np.array([float(np.linalg.norm(j.translation)) for j in self.joints]) + np.where(np.isfinite(stroke), stroke, 0.0)
        step[-1] += float(np.linalg.norm(self.tool_translation))
        return float(np.max(self.carries.T.astype(float) @ step))

    @property
    def n_params_per_joint(self) -> int:
        """Standard parameters per joint: the 10 inertial ones and the drive terms."""
        return len(INERTIAL_TERMS) + len(self.drive_terms)

    @property
    def n_params(self) -> int:
        """Number of standard parameters: ``n_dof * (10 + len(drive_terms))`` plus the coupling ones."""
        return self.n_dof * self.n_params_per_joint + self.transmission.n_coupled_params

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of the standard parameters, joint by joint (eq. 5 order, then drive terms), then the
        coupled motors' parameters."""
        terms = INERTIAL_TERMS + self.drive_terms
        joint = tuple(parameter_name(t, j) for j in range(self.n_dof) for t in terms)
        return joint + self.transmission.coupled_parameter_names

    def kinematic_fingerprint(self) -> str:
        """A short hash of what gives the base parameters their meaning: the joint frames and axes, the tool frame,
        gravity and the transmission's gear ratios and coupling (not the nominal inertia, the friction model or the
        limits, which an identification does not depend on in that way).

        Returns
        -------
        str
            16 hexadecimal digits (SHA-256 of the values rounded to 12 significant digits: the same for a description
            read again, or from a URDF and a TOML that state the same frames).
        """
        import hashlib

        values = [np.asarray(x, dtype=float).ravel() for j in self.joints for x in (j.rotation, j.translation, j.axis)]
        values += [np.asarray(x, dtype=float).ravel() for x in (self.tool_rotation, self.tool_translation, self.gravity,
                                                                 self.transmission.motor_from_joint)]
        if self.prismatic.any():  # a revolute chain's fingerprint stays what it was
            values.append(self.prismatic.astype(float))
        if self.is_tree:  # so does a serial chain's
            values.append(self.parents.astype(float))
        if self.followers:  # and a robot's without joints that follow others
            values.append(np.array([v for j in self.followers for v in (j, *self.joints[j].mimic)], dtype=float))  # type: ignore[misc]
        flat = np.concatenate(values)
        text = ",".join(f"{0.0 if abs(v) < 1e-12 else v:.12g}" for v in flat)
        return hashlib.sha256(f"{self.n_dof};{text}".encode()).hexdigest()[:16]

    def standard_parameters(self) -> np.ndarray:
        """Nominal standard parameters.

        Returns
        -------
        (n_params,) ndarray
            In :attr:`parameter_names` order, SI units.
        """
        blocks = np.concatenate([self.inertial, self.drive], axis=1).ravel()
        return np.concatenate([blocks, self.transmission.coupled_values.ravel()])

    def with_parameters(self, phi: np.ndarray) -> Robot:
        """A copy of this robot with other nominal parameters.

        Parameters
        ----------
        phi : (n_params,) array
            Standard parameters in :attr:`parameter_names` order.

        Returns
        -------
        Robot
        """
        phi = np.asarray(phi, dtype=float)
        n_joint = self.n_dof * self.n_params_per_joint
        blocks = phi[:n_joint].reshape(self.n_dof, self.n_params_per_joint)
        tr = self.transmission
        coupled = phi[n_joint:].reshape(tr.coupled_values.shape)
        return replace(self, inertial=blocks[:, :10].copy(), drive=blocks[:, 10:] * self.drive_mask,
                       transmission=replace(tr, coupled_values=coupled.copy()))

    def link_transform(self, j: int, qj: float) -> tuple[np.ndarray, np.ndarray]:
        """Pose of link ``j``'s frame in link ``j-1``'s frame (Khalil's modified DH).

        Parameters
        ----------
        j : int
            Link index, 0-based.
        qj : float
            Joint position [rad] (or [m] for a prismatic joint).

        Returns
        -------
        R : (3, 3) ndarray
            Rotation.
        p : (3,) ndarray
            Origin [m].
        """
        r, p = self.joints[j].placement(np.array([qj]))
        return r[0], p[0]

    def submodel(self, k: int, q_rest: np.ndarray | None = None) -> Robot:
        """The first ``k`` joints, the others held still.

        Links ``k+1 .. n`` become rigidly attached to link ``k``: their inertial parameters are expressed in link ``k``'s
        frame and added to it, so link ``k`` carries the wrist (the paper's three-joint model, §4.1). The tool frame
        moves with them.

        Parameters
        ----------
        k : int
            Joints kept, ``1..n_dof``.
        q_rest : (n_dof - k,) array, optional
            Positions of the held joints [rad] (0 by default).

        Returns
        -------
        Robot
            ``k`` joints, the held links merged into link ``k``.

        Raises
        ------
        ConfigError
            If ``k`` is not in ``1..n_dof`` or ``q_rest`` has the wrong length.
        """
        n = self.n_dof
        if not 1 <= k <= n:
            raise ConfigError(f"joints must be between 1 and {n} for robot {self.name!r}, got {k}")
        if self.is_tree and k < n:
            raise ConfigError(f"robot {self.name!r} has branches: holding its last {n - k} joints onto joint {k} "
                              "applies to a serial chain; hold a branch's joints in its description (held = [...])")
        q_rest = np.zeros(n - k) if q_rest is None else np.asarray(q_rest, dtype=float)
        if q_rest.shape != (n - k,):
            raise ConfigError(f"expected {n - k} rest angles for the held joints, got {q_rest.shape}")
        inertial = self.inertial[:k].copy()
        rot, pos = np.eye(3), np.zeros(3)  # pose of link j in link k-1's... accumulated in link k
        for j in range(k, n):
            r, p = self.link_transform(j, q_rest[j - k])
            pos = pos + rot @ p
            rot = rot @ r
            inertial[k - 1] += transform_inertial(self.inertial[j], rot, pos)
        tool_t = pos + rot @ self.tool_translation
        tool_r = rot @ self.tool_rotation
        return Robot(
            name=self.name,
            joints=self.joints[:k],
            gravity=self.gravity.copy(),
            inertial=inertial,
            drive_terms=self.drive_terms,
            drive=self.drive[:k].copy(),
            drive_gains=self.drive_gains[:k].copy(),
            coulomb_velocity=self.coulomb_velocity[:k].copy(),
            stribeck_velocity=self.stribeck_velocity[:k].copy(),
            limits=self.limits.subset(k),
            tool_rotation=tool_r,
            tool_translation=tool_t,
            notes=self.notes,
            transmission=self.transmission.subset(k),
            drive_mask=self.drive_mask[:k].copy(),
            nominal_problems=self.nominal_problems,
            nominal_notes=self.nominal_notes,
        )


    def without_drive_terms(self, terms, *, note: str = "") -> Robot:
        """The same robot without some drive terms (e.g. no rotor inertia ``Ia`` where a joint torque sensor on the
        link side measures the torque); ``note`` joins :attr:`nominal_notes`.

        Parameters
        ----------
        terms : sequence of str
            Names of :attr:`drive_terms` to drop; those the robot does not have are ignored.
        note : str
            A line said among the identification's warnings ("" for none).

        Returns
        -------
        Robot
        """
        keep = [i for i, t in enumerate(self.drive_terms) if t not in set(terms)]
        notes = self.nominal_notes + ((note,) if note else ())
        if len(keep) == len(self.drive_terms):
            return replace(self, nominal_notes=notes)
        return replace(self, drive_terms=tuple(self.drive_terms[i] for i in keep), drive=self.drive[:, keep].copy(),
                       drive_mask=np.asarray(self.drive_mask, dtype=bool)[:, keep].copy(), nominal_notes=notes)


def default_limits(n: int) -> Limits:
    """Limits that constrain nothing (``±inf``).

    Parameters
    ----------
    n : int
        Number of joints.

    Returns
    -------
    Limits
    """
    inf = np.full(n, np.inf)
    return Limits(-inf, inf.copy(), inf.copy(), inf.copy(), inf.copy())


__all__ = ["Joint", "Limits", "Robot", "default_limits", "DEFAULT_DRIVE_TERMS"]
