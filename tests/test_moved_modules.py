"""Old import paths of ``dynid.experiment`` keep working for a release, say where the module went, and give the very
same objects (docs/changelog.md)."""

import importlib
import subprocess
import sys
import warnings

import pytest

from dynid.experiment import MOVED


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_module_path_warns_and_is_the_new_module(old):
    new = importlib.import_module(MOVED[old])
    sys.modules.pop(f"dynid.experiment.{old}", None)
    with pytest.warns(FutureWarning, match=f"dynid.experiment.{old} moved to {MOVED[old]}"):
        aliased = importlib.import_module(f"dynid.experiment.{old}")
    assert aliased is new
    assert new.__spec__.name == MOVED[old] and new.__name__ == MOVED[old]  # the alias leaves the module's identity


def test_the_old_paper_names_warn_and_are_the_new_objects():
    from dynid.studies.paper import run_paper_experiment

    code = ("import warnings; warnings.simplefilter('error')\n"
            "from dynid.experiment import run_paper_experiment")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode != 0 and "moved to dynid.studies.paper" in out.stderr
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        import dynid.experiment as old

        assert old.run_paper_experiment is run_paper_experiment


def test_every_moved_module_exists_and_no_old_file_is_left():
    from pathlib import Path

    import dynid

    root = Path(dynid.__file__).parent
    assert [p.name for p in (root / "experiment").glob("*.py")] == ["__init__.py"]
    for new in MOVED.values():
        assert (root.parent / (new.replace(".", "/") + ".py")).exists(), new


@pytest.mark.parametrize("old", sorted(__import__("dynid").MOVED_MODULES))
def test_a_loose_top_level_module_grouped_into_a_package_keeps_its_old_path_for_a_release(old):
    """issue "Parts carry their settings, one route", item 4: the loose top-level modules are grouped into
    ``dynid.runtime`` (where the work runs) and ``dynid._util`` (the API's and configs' helpers); the old path is the
    very same module, with a FutureWarning naming the new one, and no file is left at the old path."""
    from pathlib import Path

    import dynid

    new_name = dynid.MOVED_MODULES[old]
    new = importlib.import_module(new_name)
    sys.modules.pop(old, None)
    with pytest.warns(FutureWarning, match=f"{old} moved to {new_name}"):
        aliased = importlib.import_module(old)
    assert aliased is new and new.__name__ == new_name
    root = Path(dynid.__file__).parent
    assert not (root.parent / (old.replace(".", "/") + ".py")).exists() and Path(new.__file__).parent.name == new_name.split(".")[1]


@pytest.mark.parametrize("old", sorted(__import__("dynid.io").io.MOVED))
def test_an_io_module_of_0_1_0_keeps_its_old_path_for_a_release(old):
    """issue "One route, four named parts", item 3: ``dynid.io`` grouped by job into ``config``, ``logs`` and
    ``exported``; each module 0.1.0 had imports from its old path as the very same module, with a FutureWarning naming
    the new one, and no file is left at the old path."""
    from pathlib import Path

    import dynid.io

    new_name = dynid.io.MOVED[old]
    new = importlib.import_module(new_name)
    sys.modules.pop(old, None)
    with pytest.warns(FutureWarning, match=f"{old} moved to {new_name}"):
        aliased = importlib.import_module(old)
    assert aliased is new and new.__name__ == new_name
    root = Path(dynid.io.__file__).parent
    assert not (root / f"{old.rsplit('.', 1)[1]}.py").exists()
    assert Path(new.__file__).parent.name == new_name.split(".")[2]


def test_io_holds_only_its_rooms_and_the_two_modules_every_room_shares():
    from pathlib import Path

    import dynid.io

    root = Path(dynid.io.__file__).parent
    assert sorted(p.name for p in root.glob("*.py")) == ["__init__.py", "files.py", "results.py"]
    assert sorted(p.name for p in root.iterdir() if (p / "__init__.py").exists()) == ["config", "exported", "logs"]


def test_no_two_modules_share_a_name_unless_they_are_one_kind_of_thing():
    """issue "One route, four named parts", item 3: a module's name says which it is wherever it is imported from; the
    artificial bee colony's optimiser (``optim``) and its estimator (``estimators``) keep the one name the field gives
    them."""
    from collections import Counter
    from pathlib import Path

    import dynid

    names = Counter(p.name for p in Path(dynid.__file__).parent.rglob("*.py") if p.name != "__init__.py")
    assert {name for name, n in names.items() if n > 1} == {"bee_colony.py"}
