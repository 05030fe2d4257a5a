"""The public API (issue 19, item 4): every top-level name resolves, lazily, to what its module defines."""

import subprocess
import sys
import warnings

import pytest
from conftest import PROJECT_ROOT

import replication
from replication.filters.registry import builders


def test_import_replication_loads_no_numerical_library():
    command = [sys.executable, "-c", "import sys, replication; print(' '.join(sys.modules))"]
    result = subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    loaded = {name.split(".")[0] for name in result.stdout.split()}
    assert "replication" in loaded and not loaded & {"numpy", "scipy", "cv2", "pandas", "matplotlib", "numba"}


@pytest.mark.parametrize("name", replication.__all__)
def test_every_public_name_resolves_to_its_module(name):
    value = getattr(replication, name)
    module = replication._module_of().get(name)
    if hasattr(value, "__qualname__"):  # a class or function is the one its module defines, not a copy
        assert value.__module__ == module and getattr(sys.modules[module], name) is value
    assert name in dir(replication)


def test_every_registered_filter_is_a_public_name():
    for builder in builders().values():
        assert getattr(replication, builder.__name__) is builder


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="has no attribute 'Kalman'"):
        replication.Kalman  # noqa: B018
    assert not hasattr(replication, "numpy")


def test_the_api_reference_builds_without_warnings(tmp_path):
    """pdoc (the ``docs`` extra) documents every public name on the one page, warning about none."""
    pdoc = pytest.importorskip("pdoc")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pdoc.pdoc("replication", output_directory=tmp_path)
    assert not [str(w.message) for w in caught if "pdoc" in w.filename]
    page = (tmp_path / "replication.html").read_text()
    assert all(f'id="{name}"' in page for name in replication.__all__)
