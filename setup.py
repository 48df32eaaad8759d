"""Builds the extension module `pnpba._pnpba` and its plugins with CMake for pip.

The module and its plugins are built by the project's own CMake (only the targets the module
needs, no tests or tools) in build-python/cmake, or in the CMake build folder named by
PNPBA_CMAKE_BUILD_DIR (an existing build: nothing is reconfigured). The plugins go beside the
module in pnpba/pnpba/, where the module looks for them (core/src/plugin.cpp).
"""
import glob
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE = os.path.dirname(os.path.abspath(__file__))
os.makedirs(os.path.join(SOURCE, "build-python"), exist_ok=True)  # egg_base must exist


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("PNPBA_CMAKE_BUILD_DIR")
        if not build:
            build = os.path.join(SOURCE, "build-python", "cmake")
            launcher = ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"] if shutil.which("ccache") else []
            subprocess.check_call(["cmake", "-S", SOURCE, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                                   f"-DPython_EXECUTABLE={sys.executable}",
                                   "-DPNPBA_BUILD_TESTS=OFF", "-DPNPBA_BUILD_BENCH=OFF",
                                   "-DPNPBA_BUILD_APPS=OFF", "-DPNPBA_BUILD_PYTHON=ON", *launcher])
        jobs = os.environ.get("PNPBA_BUILD_JOBS", "2")
        subprocess.check_call(["cmake", "--build", build, "-j", jobs, "--target", "pnpba_python",
                               "pnpba_open3d", "pnpba_open3d_odometry",
                               "pnpba_imgcodecs"])
        module = glob.glob(os.path.join(build, "python", "pnpba", "_pnpba*.so"))
        if len(module) != 1:
            raise RuntimeError(f"{build}: expected one built _pnpba module, found {module}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copy2(module[0], target)
        plugins = os.path.join(os.path.dirname(target), "pnpba")
        os.makedirs(plugins, exist_ok=True)
        for plugin in glob.glob(os.path.join(build, "lib", "pnpba", "libpnpba_*.so")):
            shutil.copy2(plugin, plugins)


setup(ext_modules=[Extension("pnpba._pnpba", sources=[])], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": "build-python"}, "egg_info": {"egg_base": "build-python"}})
