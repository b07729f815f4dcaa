"""The wheel's build (pyproject.toml): CMake builds the target evldt_python, the package evldt as
the C++ build lays it out (the extension _evldt, the wrapper, the LCM message types), and setuptools
packs that folder."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        given = os.environ.get("EVLDT_CMAKE_BUILD_DIR")
        build_dir = Path(given).resolve() if given else Path(self.build_temp).resolve() / "cmake"
        if not (build_dir / "CMakeCache.txt").exists():
            # A fresh build, for the interpreter pip runs (a folder configured already keeps its own).
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                            f"-DPython3_EXECUTABLE={sys.executable}"], check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "evldt_python", "--parallel", str(os.cpu_count() or 1)],
                       check=True)
        built = build_dir / "python" / "evldt"
        if not (built / "__init__.py").exists():
            sys.exit(f"evldt: CMake built no Python module in {built} (pybind11-dev and python3-dev are needed)")
        package = Path(self.get_ext_fullpath(ext.name)).parent
        shutil.copytree(built, package, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__"))
        extension = next(built.glob("_evldt*.so"))
        if extension.name != Path(self.get_ext_fullpath(ext.name)).name:
            sys.exit(f"evldt: the extension {extension.name} was built for another Python than this one ({sys.version.split()[0]})")


setup(packages=[], ext_modules=[CMakeExtension("evldt._evldt")], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": "build/python-wheel"}, "egg_info": {"egg_base": "build/python-wheel"}})
