"""Every module of the Python package is installed: wrap/meson.build lists the package's files one
by one (py.install_sources), and a module missing from the list is absent from an installed
package (beamstops.studies.options once was: every study then failed with ModuleNotFoundError)."""

from __future__ import annotations

import re

from conftest import ROOT


def test_every_python_file_of_the_package_is_in_the_install_list() -> None:
    listed = set(re.findall(r"'(beamstops/[^']+\.py)'", (ROOT / "wrap" / "meson.build").read_text()))
    present = {path.relative_to(ROOT / "wrap").as_posix() for path in (ROOT / "wrap" / "beamstops").rglob("*.py")}
    assert present - listed == set(), "not installed"
    assert listed - present == set(), "listed but absent"
