"""moo's top-level entry points: each is the object of its defining module, loaded on first use."""

import importlib
import subprocess
import sys

import pytest

import moo


@pytest.mark.parametrize("name", moo.__all__)
def test_entry_point_is_the_defining_modules_object(name):
    module = importlib.import_module(moo._EXPORTS[name])
    assert getattr(moo, name) is getattr(module, name)
    assert name in dir(moo)


def test_import_moo_is_cheap_and_unknown_names_raise():
    code = "import sys, moo; print('pymoo' in sys.modules, 'robustctl' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "False"]
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        moo.nope  # noqa: B018


def test_all_lists_exactly_the_lazy_exports():
    assert sorted(moo.__all__) == sorted(moo._EXPORTS)
