"""python/CMakeLists.txt's install rules: `cmake --install` puts a package Debian's python3
imports from PREFIX/lib/python3/dist-packages, with no build tree on the path."""

import os
import pathlib
import subprocess
import sys

import pytest

BUILD = os.environ.get("SONARBENCH_BUILD_DIR")


@pytest.mark.skipif(BUILD is None, reason="run by ctest, which names the build directory")
def test_the_installed_package_imports_and_simulates(tmp_path):
    subprocess.run(["cmake", "--install", BUILD, "--prefix", tmp_path / "prefix"], check=True,
                   capture_output=True)
    package = tmp_path / "prefix/lib/python3/dist-packages/sonarbench"
    assert {"__init__.py", "_core.pyi", "py.typed"} <= {p.name for p in package.iterdir()}
    source = pathlib.Path(os.environ["SONARBENCH_SOURCE_DIR"])
    code = ("import sonarbench as sb; s = sb.load_scene(%r); "
            "print(sb.__file__, sb.Simulator(s).sweep(0).intensities.shape)"
            % str(source / "scenes/cras-tank.yaml"))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(package.parent)
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                         text=True, env=env, cwd=tmp_path).stdout.split()
    assert pathlib.Path(out[0]).is_relative_to(package)
    assert out[1:] == ["(200,", "399)"]
