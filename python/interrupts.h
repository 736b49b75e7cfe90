#pragma once
// Ctrl-C during a long call from Python: the engine calls check_signals between its chunks
// (EngineOptions::between_chunks), which runs Python's signal handlers there; an exception one of
// them raises (KeyboardInterrupt) ends the call.

#include <pybind11/pybind11.h>

#include "caliber/engine.h"

namespace caliber_python {

/// Runs Python's pending signal handlers (the GIL taken for it); a handler's exception ends the
/// call as a Python exception.
inline void check_signals() {
  pybind11::gil_scoped_acquire hold;
  if (PyErr_CheckSignals() != 0) throw pybind11::error_already_set();
}

/// Engine options whose long calls stop on Ctrl-C.
inline caliber::EngineOptions interruptible(caliber::EngineOptions options) {
  options.between_chunks = check_signals;
  return options;
}

}  // namespace caliber_python
