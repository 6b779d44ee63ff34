#pragma once
// wul3d._wul3d._run: the library's run loop (wul3d/run.hpp), `wul3d run` as one call.
#include <pybind11/pybind11.h>

namespace wul3d::python {
/// Adds `_run` when the library has its run loop (include/wul3d/run.hpp).
void bind_run(pybind11::module_& m);
/// Adds `_check_write_target`, `_OutputLock` and `_remove_stale_temporaries`: the library's
/// guard of every write (wul3d/write_guard.hpp), for the batch's own folders.
void bind_write_guard(pybind11::module_& m);
}  // namespace wul3d::python
