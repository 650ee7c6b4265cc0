"""The package's namespace is its API: ``dir(platen)`` and ``from platen import *`` show the
documented functions and exceptions, not the modules the package uses inside."""

import platen


def test_dir_is_the_public_api():
    names = dir(platen)
    assert names == sorted(platen.__all__ + ["__version__"])
    for inner in ["np", "os", "json", "csv", "io", "math", "numbers", "Any", "Dict", "Mapping", "_platen"]:
        assert inner not in names, inner
    for name in platen.__all__:
        assert callable(getattr(platen, name)), name


def test_star_import_brings_the_api_only():
    scope: dict = {}
    exec("from platen import *", scope)
    assert sorted(k for k in scope if not k.startswith("__")) == sorted(platen.__all__)
