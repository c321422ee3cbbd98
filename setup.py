"""Builds the Python package kdm for pip: the pure-Python files of python/kdm and the compiled module
kdm._kdm, which CMake builds (Release, only its target) in build-python/ for the interpreter running this.

pyproject.toml says how to call it; scripts/install-python is the one-command install.
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
BUILD = ROOT / "build-python"  # shared with scripts/install-python, so a second build is incremental
BUILD.mkdir(exist_ok=True)


def version():
    """The library's version, from CMakeLists.txt's project() line (kdm.__version__ is the same)."""
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(kdm VERSION ([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(BUILD), "-DCMAKE_BUILD_TYPE=Release",
            f"-DPython3_EXECUTABLE={sys.executable}", "-DKDM_PYTHON=ON", "-DKDM_BUILD_TOOLS=OFF",
            "-DKDM_BUILD_TESTS=OFF", "-DKDM_BUILD_BENCHMARKS=OFF", "-DKDM_INSTALL=OFF",
        ]
        subprocess.check_call(configure)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 2))
        subprocess.check_call(["cmake", "--build", str(BUILD), "--target", "kdm_python", "-j", jobs])
        built = next((BUILD / "python" / "kdm").glob("_kdm*.so"))
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(
    version=version(),
    packages=["kdm"],
    package_dir={"": "python"},
    package_data={"kdm": ["py.typed", "*.pyi"]},
    ext_modules=[Extension("kdm._kdm", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # setuptools' work files go under build-python/ too: build/ is the CMake build of the README.
    options={"build": {"build_base": str(BUILD / "setuptools")}, "egg_info": {"egg_base": str(BUILD)}},
    zip_safe=False,
)
