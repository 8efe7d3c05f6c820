"""Rigid-body helpers: rotations and the change of frame of the ten inertial parameters."""

from __future__ import annotations

import numpy as np


def skew(v: np.ndarray) -> np.ndarray:
    """The skew-symmetric matrix ``S(v)`` with ``S(v) @ w == cross(v, w)``.

    Parameters
    ----------
    v : (3,) array

    Returns
    -------
    (3, 3) array
    """
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rot_x(a: float) -> np.ndarray:
    """Rotation about x.

    Parameters
    ----------
    a : float [rad]

    Returns
    -------
    (3, 3) array
    """
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_z(a: float) -> np.ndarray:
    """Rotation about z.

    Parameters
    ----------
    a : float [rad]

    Returns
    -------
    (3, 3) array
    """
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_axis(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Batched Rodrigues rotations about a fixed unit axis.

    Parameters
    ----------
    axis : (3,) array
        Unit axis.
    angle : (N,) array [rad]

    Returns
    -------
    (N, 3, 3) array
    """
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    k = skew(axis)
    k2 = k @ k
    return np.eye(3) + s[:, None, None] * k + (1.0 - c)[:, None, None] * k2


def inertia_matrix(p: np.ndarray) -> np.ndarray:
    """The 3×3 inertia matrix of six inertia parameters.

    Parameters
    ----------
    p : (6,) array [kg·m²]
        XX, XY, XZ, YY, YZ, ZZ (eq. 5 order).

    Returns
    -------
    (3, 3) array
    """
    xx, xy, xz, yy, yz, zz = p
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def inertia_vector(m: np.ndarray) -> np.ndarray:
    """The six inertia parameters of a 3×3 inertia matrix (inverse of :func:`inertia_matrix`).

    Parameters
    ----------
    m : (3, 3) array [kg·m²]

    Returns
    -------
    (6,) array
        XX, XY, XZ, YY, YZ, ZZ.
    """
    return np.array([m[0, 0], m[0, 1], m[0, 2], m[1, 1], m[1, 2], m[2, 2]])


def inertial_from_physical(mass: float, com: np.ndarray, inertia_com: np.ndarray) -> np.ndarray:
    """Ten standard inertial parameters (eq. 5 order) about the frame origin.

    Parameters
    ----------
    mass : float
        Link mass [kg].
    com : (3,) array
        Centre of mass in the link frame [m].
    inertia_com : (3, 3) array
        Inertia tensor about the centre of mass, link frame axes [kg·m²].

    Returns
    -------
    (10,) array ``[XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M]`` (parallel-axis theorem).
    """
    com = np.asarray(com, dtype=float)
    s = skew(com)
    inertia_origin = np.asarray(inertia_com, dtype=float) + mass * (s.T @ s)
    return np.concatenate([inertia_vector(inertia_origin), mass * com, [mass]])


def transform_inertial(phi: np.ndarray, rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """A body's ten inertial parameters expressed in another frame A:
    ``I_A = R I_B Rᵀ - m S(p)S(p) - S(p)S(c) - S(c)S(p)`` with ``c = R·MS_B``, ``MS_A = c + m p``.

    Parameters
    ----------
    phi : (10,) array
        Given in frame B (eq. 5 order, about B's origin).
    rotation : (3, 3) array
        ``A_R_B``.
    translation : (3,) array [m]
        The origin of B in A.

    Returns
    -------
    (10,) array
        About the origin of A, in A's axes.
    """
    r = np.asarray(rotation, dtype=float)
    p = np.asarray(translation, dtype=float)
    m = phi[9]
    c = r @ phi[6:9]
    sp, sc = skew(p), skew(c)
    inertia = r @ inertia_matrix(phi[:6]) @ r.T - m * sp @ sp - sp @ sc - sc @ sp
    return np.concatenate([inertia_vector(inertia), c + m * p, [m]])


def pseudo_inertia(phi: np.ndarray) -> np.ndarray:
    """The 4×4 pseudo-inertia ``[[½ tr(I)·1 - I, h], [hᵀ, m]]`` of ten inertial parameters; positive semidefinite
    exactly for a real mass distribution (Wensing, Kim & Slotine, IEEE RA-L 3(1), 2018).

    Parameters
    ----------
    phi : (10,) array
        Eq. 5 order, about the link origin.

    Returns
    -------
    (4, 4) array
    """
    inertia = inertia_matrix(phi[:6])
    sigma = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    h = np.asarray(phi[6:9], dtype=float)
    return np.block([[sigma, h[:, None]], [h[None, :], np.array([[phi[9]]])]])


CONSISTENCY_TOL = 1e-7
"""The semidefinite solver's accuracy: base parameters count as physically consistent when their consistency margin is
at least -1e-7 times the largest of them (at least 1; :func:`within_round_off`), an SDP result when its smallest
pseudo-inertia eigenvalue is at least -1e-7, and a friction at least that far below 0 is the solver's 0."""


def within_round_off(value: float, values=None) -> bool:
    """Whether ``value`` is at least 0 to the solver's round-off: ``-CONSISTENCY_TOL`` times the largest ``|values|``
    where it exceeds 1 (the solver is accurate relative to the size of the parameters it is given: a KR 300's base
    parameters reach 2,200, and its SDP estimate, consistent to 8e-10 link by link, had a margin of -4e-7).

    Parameters
    ----------
    value : float
        A consistency margin [kg·m²], or a term bounded below by 0 (a friction).
    values : array, optional
        The parameters it comes from (non-finite ones: a scale of 1).

    Returns
    -------
    bool
    """
    finite = values is not None and np.size(values) and np.all(np.isfinite(values))
    scale = max(1.0, float(np.max(np.abs(values)))) if finite else 1.0
    return bool(value >= -CONSISTENCY_TOL * scale)


def is_physically_consistent(phi: np.ndarray, tol: float = 1e-9) -> bool:
    """Whether ten inertial parameters are those of a real mass distribution: their pseudo-inertia is positive
    semidefinite (Wensing, Kim & Slotine, IEEE RA-L 3(1), 2018).

    Parameters
    ----------
    phi : (10,) array
        XX..ZZ [kg·m²], MX, MY, MZ [kg·m], M [kg] about the link origin (eq. 5).
    tol : float
        Tolerance on the smallest eigenvalue.

    Returns
    -------
    bool
    """
    return bool(np.linalg.eigvalsh(pseudo_inertia(phi)).min() >= -tol * max(1.0, abs(phi[9])))


def nearest_consistent(phi: np.ndarray, floor: float = 1e-6) -> np.ndarray:
    """The physically consistent inertial parameters nearest to ``phi``: its pseudo-inertia's negative eigenvalues
    raised to a small positive floor (the Frobenius-nearest positive definite pseudo-inertia; Wensing, Kim & Slotine,
    IEEE RA-L 3(1), 2018), mapped back. Consistent parameters come back unchanged.

    Parameters
    ----------
    phi : (10,) array
        Eq. 5 order, about the link origin.
    floor : float
        Smallest eigenvalue kept, relative to the largest (a positive definite result, as a log-det prior needs).

    Returns
    -------
    (10,) ndarray
    """
    phi = np.asarray(phi, dtype=float)
    if is_physically_consistent(phi, tol=0.0):
        return phi.copy()
    ev, vec = np.linalg.eigh(pseudo_inertia(phi))
    j = (vec * np.maximum(ev, floor * max(float(ev.max()), 1e-12))) @ vec.T
    sigma = j[:3, :3]
    inertia = np.trace(sigma) * np.eye(3) - sigma  # Σ = ½ tr(I)·1 - I  ⇔  I = tr(Σ)·1 - Σ
    return np.concatenate([inertia_vector(inertia), j[:3, 3], [j[3, 3]]])


def physical_from_inertial(phi: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia about the centre of mass of ten inertial parameters; the inverse of
    :func:`inertial_from_physical`. A massless link gives a zero centre of mass.

    Parameters
    ----------
    phi : (10,) array
        Eq. 5 order, about the link origin.

    Returns
    -------
    mass : float [kg]
    com : (3,) array [m]
        In the link frame.
    inertia : (3, 3) array [kg·m²]
        About the centre of mass, link frame axes.
    """
    phi = np.asarray(phi, dtype=float)
    mass = float(phi[9])
    com = phi[6:9] / mass if mass > 0 else np.zeros(3)
    s = np.array([[0, -com[2], com[1]], [com[2], 0, -com[0]], [-com[1], com[0], 0]])
    return mass, com, inertia_matrix(phi[:6]) - mass * (s.T @ s)


def physical_problems(phi: np.ndarray, tol: float = 1e-9) -> list[str]:
    """The physical-consistency rules that ten inertial parameters break: positive mass, inertia about the centre
    of mass positive definite, and its principal moments meeting the triangle inequality (each at most the sum of the
    other two). A zero mass with zero first moments and inertia (a massless link lumped into its neighbour) breaks the
    first rule but no other; a singular inertia (a point mass, a thin rod: principal moments within ``tol`` of zero) is
    said as such, the limit of a real link rather than an impossible one.

    Parameters
    ----------
    phi : (10,) array
        Eq. 5 order, about the link origin.
    tol : float
        Relative tolerance.

    Returns
    -------
    list of str
        One line per rule broken; empty when none.
    """
    phi = np.asarray(phi, dtype=float)
    mass = float(phi[9])
    if not mass > 0:
        return [f"mass {mass:.6g} kg is not positive"]
    ev = np.linalg.eigvalsh(physical_from_inertial(phi)[2])
    scale = max(abs(ev).max(), 1e-12)
    if ev.min() < -tol * scale:
        return [f"inertia about the COM is not positive definite (principal moments {_fmt(ev)} kg·m²)"]
    out = []
    if ev.min() <= tol * scale:
        shape = "a point mass" if ev.max() <= 1e-12 else "a thin rod"
        shown = np.where(abs(ev) <= tol * scale, 0.0, ev)
        out.append(f"inertia about the COM is singular (principal moments {_fmt(shown)} kg·m²: {shape}, the limit "
                   "of a real link)")
    if 2 * ev.max() > ev.sum() * (1 + 1e-9) + tol * scale:
        out.append(f"principal moments {_fmt(ev)} kg·m² break the triangle inequality")
    return out


def _fmt(values) -> str:
    return "[" + ", ".join(f"{v:.4g}" for v in values) + "]"
