// `_gdpt_cpu`: the x86-64 micro-architecture level this CPU runs, as GCC's run-time checks see it
// (CPUID, and for AVX the operating system's XSAVE support). The add-on asks it before choosing
// between the baseline and the x86-64-v3 build of `_gdpt` (blender_addon/gdpt/native.py). It is a
// module of its own, always built for the baseline, because importing one build of `_gdpt` to ask
// would rule out the other: pybind11 registers each C++ type once per process.
#include <pybind11/pybind11.h>

namespace {

int x86_64_level() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("x86-64-v4")) return 4;
  if (__builtin_cpu_supports("x86-64-v3")) return 3;
  if (__builtin_cpu_supports("x86-64-v2")) return 2;
  return 1;
}

}  // namespace

PYBIND11_MODULE(_gdpt_cpu, m) {
  m.doc() = "The CPU's x86-64 micro-architecture level (1-4), for choosing a build of _gdpt";
  m.def("x86_64_level", &x86_64_level,
        "1 = baseline x86-64, 2 = x86-64-v2, 3 = x86-64-v3 (AVX2, FMA, BMI2), 4 = x86-64-v4");
}
