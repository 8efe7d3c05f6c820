"""The model files a results.json hands on, in dynid's own files or written into the user's
(:mod:`dynid.io.exported.export`, :mod:`dynid.io.exported.urdf_write_back`, :mod:`dynid.io.exported.mjcf_write_back`): the one place
``dynid identify`` and ``dynid export`` get their URDF and MJCF texts from."""

from __future__ import annotations

from .export import consistent_estimate, file_parameters, mjcf_from_results, urdf_from_results, with_note
from .mjcf_write_back import mjcf_written_back
from .urdf_write_back import urdf_written_back

__all__ = ["written_model"]


def written_model(form: str, robot, results: dict, source: str = "results", *, users_file=None,
                  out_dir=None) -> tuple[str, list[str]]:
    """The URDF or MJCF text a results.json hands on: its physically consistent estimate
    (:func:`dynid.io.exported.export.consistent_estimate`) as the results chose the files to hold it
    (:func:`dynid.io.exported.export.file_parameters`), in dynid's own file (:func:`dynid.io.exported.export.urdf_from_results`,
    :func:`~dynid.io.exported.export.mjcf_from_results`) or written into the user's, with the note of what differs from dynid's
    model at its end.

    Parameters
    ----------
    form : {"URDF", "MJCF"}
    robot : Robot
        The robot's description the results were identified for.
    results : dict
        results.json.
    source : str
        Where the results come from, named in errors.
    users_file : str or Path, optional
        The user's own URDF or MJCF to write the values into.
    out_dir : str or Path, optional
        Where a user's MJCF will be written (its relative paths are rewritten for it).

    Returns
    -------
    text : str
    moved : list of str
        Links whose values moved far from the user's file's own (none for dynid's own file).

    Raises
    ------
    ConfigError
        As :func:`dynid.io.exported.export.consistent_estimate` and :func:`~dynid.io.exported.export.file_parameters`, or a user's file
        that is not the robot's.
    """
    if users_file is None:
        return (urdf_from_results if form == "URDF" else mjcf_from_results)(robot, results, source=source), []
    fitted, phi = consistent_estimate(robot, results, source)
    phi, note = file_parameters(fitted, phi, results, source, form)
    text, moved = (urdf_written_back(users_file, fitted, phi) if form == "URDF" else
                   mjcf_written_back(users_file, fitted, phi, out_dir=out_dir, offsets_held=True))
    return with_note(text, note), moved
