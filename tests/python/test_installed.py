"""The module works from an installed tree: `cmake --install` to a temporary prefix, then
/usr/bin/python3 imports it from there (and not from the build tree)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

BUILD = os.environ.get("ARTCAL_BUILD_DIR")


@pytest.mark.skipif(not BUILD, reason="ARTCAL_BUILD_DIR not set (ctest sets it)")
def test_installed_module_imports_and_evaluates(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", BUILD, "--prefix", str(prefix)], check=True,
                   capture_output=True)
    packages = [p.parent for p in prefix.rglob("artcal/__init__.py")]
    assert len(packages) == 1, packages
    site = packages[0].parent
    assert site.name in ("dist-packages", "site-packages")
    assert (site / "artcal" / "__init__.pyi").is_file() and (site / "artcal" / "py.typed").is_file()
    root = Path(__file__).resolve().parents[2]
    code = ("import artcal, sys; p = artcal.Plan('plans/paper-2r-5bars.json'); "
            "r = p.evaluate(); assert r['identifiable']; print(artcal.__file__)")
    env = {"PATH": os.environ.get("PATH", "/usr/bin"), "PYTHONPATH": str(site)}
    done = subprocess.run(["/usr/bin/python3", "-c", code], cwd=root, env=env, check=True,
                          capture_output=True, text=True)
    assert done.stdout.strip().startswith(str(site))
