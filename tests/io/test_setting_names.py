"""docs/configuration.md's "Where a setting lives" held to the code: each table's keys are its record's fields of the
same name, but those the table says are held under another name (and those must be held there)."""

import dataclasses
import importlib
import re
from pathlib import Path

import msgspec
import pytest

from dynid.io.config import config_types
from dynid.simulation.closed_loop import Controller

DOC = Path(__file__).resolve().parents[2] / "docs" / "configuration.md"

TYPED = {"[identification]": config_types.DatasetTable, "[preprocessing]": config_types.PreprocessingTable,
         "[estimation]": config_types.EstimationTable, "[controller]": config_types.ControllerTable,
         "[drive_gains]": config_types.DriveGainsTable}
"""Each table of the doc's first column and the typed table a config's is read by."""


def _rows() -> list[tuple[str, str, str]]:
    text = DOC.read_text(encoding="utf-8")
    section = text.split("## Where a setting lives", 1)[1].split("\n## ", 1)[0]
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in section.splitlines()
            if line.startswith("| `[")]
    return [(re.findall(r"`(\[[^`]+\])`", table)[0], record.strip("`"), moved) for table, record, moved in rows]


def _record(path: str):
    module, name = path.rsplit(".", 1)
    return getattr(importlib.import_module(module), name)


def _moved(cell: str) -> dict[str, str | None]:
    """``{key: field}`` of a cell's "`a`, `b` → `field` (...)" groups; a target without a field name: None."""
    out: dict[str, str | None] = {}
    for group in filter(None, (g.strip() for g in cell.split(";"))):
        if "→" not in group:
            continue
        keys, target = group.split("→", 1)
        field = re.match(r"\s*`(\w+)`", target)
        for key in re.findall(r"`(\w+)`", keys):
            out[key] = field.group(1) if field else None
    return out


def test_the_doc_names_every_table_once():
    assert sorted(t for t, _, _ in _rows()) == sorted(TYPED)


@pytest.mark.parametrize("table", sorted(TYPED))
def test_a_key_keeps_its_name_in_its_record(table):
    record_path, cell = next((r, m) for t, r, m in _rows() if t == table)
    record = _record(record_path)
    fields = {f.name for f in dataclasses.fields(record)}
    moved = _moved(cell)
    keys = {f.encode_name for f in msgspec.structs.fields(TYPED[table])}
    assert set(moved) <= keys, f"{table}: the doc moves keys the table does not have: {sorted(set(moved) - keys)}"
    for key in sorted(keys):
        if key in moved:
            assert key not in fields, f"{table} {key}: the doc says it is held under another name, the record has it"
            assert moved[key] is None or moved[key] in fields, f"{table} {key}: {record.__name__} has no {moved[key]}"
        else:
            assert key in fields, f"{table} {key}: not a field of {record.__name__}, and the doc does not say where it is"


def test_the_controllers_keys_keep_their_names_in_the_controller():
    moved = _moved(next(m for t, _, m in _rows() if t == "[controller]"))
    fields = {f.name for f in dataclasses.fields(Controller)}
    assert {k for k, v in moved.items() if v == "controller"} <= fields
