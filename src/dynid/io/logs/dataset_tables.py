"""A dataset's table typed (msgspec): each field of ``[identification]``, ``[[validation]]`` and a payload's runs with
its type, its allowed values and a description (what editors show from the configs' JSON Schemas in
``dynid/schema/``). :func:`dynid.io.logs.dataset_specs.dataset_spec` converts a table through it into the spec the log
readers take; :mod:`dynid.io.config.config_types` holds them in the configs' documents."""

from __future__ import annotations

from typing import Annotated, Literal, Union

from msgspec import Meta

from ..._util.typed import Table

__all__ = ["Column", "PositiveHz", "SignalTable", "TimeTable", "DatasetTable"]

Column = Union[Annotated[int, Meta(ge=1)], str]
PositiveHz = Annotated[float, Meta(gt=0)]
Factor = Union[float, list[float]]


def _d(text: str) -> Meta:
    """A field's description, shown by editors from the JSON Schema."""
    return Meta(description=text)


class SignalTable(Table, kw_only=True):
    """Where one signal is: ``{ columns = [2, 3, 4, 5, 6, 7], unit = "rad" }``."""

    columns: Annotated[list[Column], _d("one per joint: 1-based numbers or header names")] | None = None
    file: Annotated[str, _d("the file, relative to the data root (default: the dataset's file)")] | None = None
    unit: Annotated[str, _d("rad or deg; rad/s or deg/s; A or mA; N*m")] | None = None
    sign: Annotated[Factor, _d("1 or -1, or one per joint: multiplies the signal")] | None = None
    scale: Annotated[Factor, _d("a non-zero factor, or one per joint: multiplies the signal")] | None = None
    side: Annotated[Literal["joint", "motor"], _d("this signal's side of the transmission (default: the dataset's)")] | None = None
    sensor: Annotated[Literal["joint", "drive"], _d(
        "torques only: joint (a joint torque sensor on the link side of the gear: the torque holds no rotor inertia, "
        "so the default drive terms leave Ia out) or drive (motor currents or a motor-side torque: the default)")] | None = None


class TimeTable(Table, kw_only=True):
    """The time stamps' column: ``time = { column = 1 }`` (seconds), ``{ column = "%time", unit = "ns" }``."""

    column: Annotated[Column, _d("1-based number or header name of the time stamps")]
    file: Annotated[str, _d("the file (default: the dataset's file)")] | None = None
    unit: Annotated[Literal["s", "ms", "us", "ns"],
                    _d("the time stamps' unit: s (default), ms, us or ns")] | None = None
    nanoseconds: Annotated[Column, _d("a column of the nanoseconds beside a column of whole seconds (ROS's "
                                      "header.stamp.sec and header.stamp.nanosec): the time is their sum")] | None = None


class DatasetTable(Table, kw_only=True):
    """A dataset: columns of CSV files, or a ROS 2 bag of sensor_msgs/JointState (:mod:`dynid.io.logs.datasets`)."""

    preset: Annotated[str, _d("ur-rtde, ur-rtde-19 or motor-side: fills in the other fields")] | None = None
    name: Annotated[str, _d("the dataset's name in tables and messages")] | None = None
    file: Annotated[str, _d("default file of every signal, relative to the data root")] | None = None
    header: Annotated[bool, _d("the first line holds column names")] | None = None
    n_columns: Annotated[int, Meta(ge=1, description="columns every line has")] | None = None
    delimiter: Annotated[str, _d("field separator (default ',')")] | None = None
    decimal: Annotated[Literal[".", ","], _d("the numbers' decimal separator: '.' (default) or ',' (a spreadsheet's "
                                             "export in a European locale, with another delimiter)")] | None = None
    rows: Annotated[list[Annotated[int, Meta(ge=1)]], Meta(min_length=2, max_length=2,
                                                           description="[first, last] 1-based inclusive data rows")] | None = None
    time_range: Annotated[list[float], Meta(min_length=2, max_length=2,
                                            description="[start, stop] s from the first row read")] | None = None
    gaps: Annotated[Literal["auto", "refuse", "interpolate"], _d("a time step over 5x the median, or missing values "
                                                                 "(empty or NaN fields): auto (default: filled when at "
                                                                 "most 20 samples, refused when longer), refuse, or "
                                                                 "interpolate (up to max_gap)")] | None = None
    max_gap: Annotated[float, Meta(gt=0, description="s: the longest gap interpolated (default 0.1)")] | None = None
    held: Annotated[Literal["interpolate", "keep"], _d("rows repeating the previous one exactly: interpolate (default) or keep")] | None = None
    time: Annotated[TimeTable, _d("the time stamps' column")] | None = None
    rate: Annotated[PositiveHz, _d("Hz, when there is no time column")] | None = None
    resample: Annotated[PositiveHz, _d("Hz: uniform grid for jittered time stamps (default 1 / median step)")] | None = None
    side: Annotated[Literal["joint", "motor"], _d("joint (default) or motor side of the transmission")] | None = None
    positions: Annotated[SignalTable, _d("joint or motor angles (rad or deg)")] | None = None
    velocities: Annotated[Union[SignalTable, bool], _d(
        "measured velocities (optional; false: none, a preset's left out and derived from the positions)"
    )] | None = None
    currents: Annotated[SignalTable, _d("motor currents: torque = drive gain · current (eq. 16)")] | None = None
    torques: Annotated[SignalTable, _d("torques [N·m], instead of currents")] | None = None
    bag: Annotated[str, _d("a ROS 2 bag's folder or a ROS 1 .bag file, relative to the data root")] | None = None
    topic: Annotated[str, _d("the bag's JointState topic (default /joint_states)")] | None = None
    joint_names: Annotated[list[str], _d("the bag's joint names, in the robot's order")] | None = None
    effort: Annotated[Literal["torques", "currents"], _d("what the bag's effort holds")] | None = None
