"""The examples in the library's docstrings run as written (doctest): every module of the
package outside the independent reference, imported and tested; an example that only
illustrates (it needs a run the docstring does not build) says ``# doctest: +SKIP``."""

import doctest
import importlib
import pkgutil

import pytest

import ukflex

MODULES = sorted(m.name for m in pkgutil.walk_packages(ukflex.__path__, "ukflex.")
                 if not m.name.startswith("ukflex.reference") and not m.name.startswith("ukflex._"))


def test_the_package_has_docstring_examples():
    finder = doctest.DocTestFinder()
    examples = sum(len(t.examples) for name in MODULES for t in finder.find(importlib.import_module(name)))
    assert examples >= 7  # the scene builder's module example alone has seven


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} docstring examples of {name} failed"
