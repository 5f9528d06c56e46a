# The add-on's C++ module, `_gdpt`, in the build that suits this CPU.
#
# `make build` compiles the core twice on a machine that runs x86-64-v3 code (AVX2, FMA, BMI2):
# the baseline build (any x86-64 CPU) next to this file, and an x86-64-v3 build in x86-64-v3/,
# which renders a few percent faster (docs/user-guide.md, "Install"). The small `_gdpt_cpu`
# module, always baseline, reports the CPU's level, and the fastest build it runs is loaded.
# GDPT_ISA=baseline or GDPT_ISA=x86-64-v3 in the environment forces one; forcing a build the CPU
# cannot run is an error message, never a crash.
#
# Only one build can live in a process (pybind11 registers each C++ type once), so the choice is
# made once, before anything imports `_gdpt`, and the chosen module is registered as
# `gdpt._gdpt`: `from . import _gdpt` anywhere then gets it.
import importlib.machinery
import importlib.util
import os
import sys

ENV = "GDPT_ISA"
# Build name -> (folder relative to this file, x86-64 level the CPU needs), fastest first.
BUILDS = {"x86-64-v3": ("x86-64-v3", 3), "baseline": ("", 1)}

_here = os.path.dirname(os.path.abspath(__file__))
_loaded = None  # (module, build name, error), once load() has run


def module_file(build):
    """Path of the `_gdpt` extension of `build` in this add-on folder, or None."""
    folder = os.path.join(_here, BUILDS[build][0])
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = os.path.join(folder, "_gdpt" + suffix)
        if os.path.isfile(path):
            return path
    return None


def cpu_level():
    """The CPU's x86-64 level (1-4) from `_gdpt_cpu`; None when that module is missing."""
    try:
        from . import _gdpt_cpu
    except ImportError:
        return None
    return _gdpt_cpu.x86_64_level()


def choose():
    """(build name, error): the build to load, from GDPT_ISA, the CPU and the files present."""
    forced = os.environ.get(ENV, "")
    if forced and forced not in BUILDS:
        return None, (f"{ENV}={forced!r} is not a build of the module; use one of "
                      f"{', '.join(sorted(BUILDS))}, or unset it to choose by CPU")
    level = cpu_level()
    if forced:
        folder, needed = BUILDS[forced]
        if needed > 1 and (level or 1) < needed:
            return None, (f"{ENV}={forced} but this CPU does not run {forced} code (its x86-64 "
                          f"level is {level or 'unknown'}); unset {ENV}")
        if module_file(forced) is None:
            return None, (f"{ENV}={forced} but the add-on has no {forced} build in "
                          f"{os.path.join(_here, folder)}; rebuild with `make build` on a CPU "
                          f"that runs it")
        return forced, None
    for build, (_, needed) in BUILDS.items():
        if (level or 1) >= needed and module_file(build) is not None:
            return build, None
    return None, f"no _gdpt module in {_here}; reinstall the add-on with scripts/install-addon.sh"


def load():
    """(module, build name, error). Loads the chosen build once per process as `gdpt._gdpt`."""
    global _loaded
    if _loaded is not None:
        return _loaded
    name = __package__ + "._gdpt"
    build, error = choose()
    if build is None:
        _loaded = (None, None, error)
        return _loaded
    try:
        spec = importlib.util.spec_from_file_location(name, module_file(build))
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    except ImportError as e:
        _loaded = (None, build, f"the {build} build of _gdpt could not be loaded: {e}")
        return _loaded
    sys.modules[name] = module
    setattr(sys.modules[__package__], "_gdpt", module)
    _loaded = (module, build, None)
    return _loaded
