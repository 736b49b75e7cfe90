// The Python module caliber (pybind11): meshes from files or numpy arrays, models that pickle,
// poses, the query kinds with numpy results, swept queries, and the parallel engine over batches,
// frames and scenes. Each class or group of functions is bound in a file of its own (common.h
// lists them); every query and step releases the GIL, so Python threads can query at once.

#include <pybind11/eval.h>

#include <dlfcn.h>

#include <filesystem>

#include "bounded_errors.h"
#include "common.h"

namespace {

/// What pickles name to rebuild a Model, a Pose or a Batch: Python functions of module caliber
/// (pickle cannot name a pybind11 function at protocols 0 and 1), calling the checked builders.
constexpr const char* kPythonPart = R"(
def _model_from_state(state):
    """How a pickled Model is rebuilt: its state checked, its BVH built again."""
    return _checked_model(state)

def _pose_from_state(translation, quaternion):
    """How a pickled Pose is rebuilt: its values checked."""
    return _checked_pose(translation, quaternion)

def _batch_from_state(state):
    """How a pickled Batch is rebuilt: its arrays checked against its offsets."""
    return _checked_batch(state)

)";

/// caliber's pure-Python modules (caliber.distributed) sit in the folder caliber/ beside the
/// module's file: with that folder as the module's __path__, `import caliber.distributed` finds them.
void set_package_path(pybind11::module_& m) {
  if (Dl_info info{}; dladdr(reinterpret_cast<const void*>(&set_package_path), &info) != 0 && info.dli_fname != nullptr) {
    pybind11::list path;
    path.append((std::filesystem::path(info.dli_fname).parent_path() / "caliber").string());
    m.attr("__path__") = path;
  }
}

}  // namespace

PYBIND11_MODULE(caliber, m) {
  namespace py = pybind11;
  using namespace caliber_python;
  m.doc() = "caliber: exact collision detection between rigid triangle meshes, parallelized by task calibration";
  m.attr("__version__") = caliber::kVersion;
  static py::exception<caliber::Error> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const caliber::Error& e) {
      error(e.what());
    }
  });
  bind_mesh(m);
  bind_model(m);
  bind_pose(m);
  set_package_path(m);
  bind_query(m);
  bind_sweep(m);
  bind_engine(m);
  bind_world(m);
  py::exec(kPythonPart, m.attr("__dict__"));
  // No object is built twice (see half_built.h).
  refuse_second<caliber::Mesh>(m.attr("Mesh"), "__init__", "Mesh");
  refuse_second<PyModel>(m.attr("Model"), "__init__", "Model");
  refuse_second<PyModel>(m.attr("Model"), "__setstate__", "Model");
  refuse_second<caliber::Pose>(m.attr("Pose"), "__init__", "Pose");
  refuse_second<caliber::Engine>(m.attr("Engine"), "__init__", "Engine");
  refuse_second<caliber::World>(m.attr("World"), "__init__", "World");
  // Last: every public function and method, as now bound, raises TypeErrors of bounded length
  // (caliber.query bounds its own: query.cpp).
  bound_type_errors(m, {"query"});
}
