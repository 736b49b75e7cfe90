// caliber.World: a scene file's objects, poses and broad phase, stepped or swept by an Engine.

#include "common.h"

namespace caliber_python {
namespace {

std::string world_repr(const caliber::World& w) {
  return (count_of(w.scene().objects.size(), "object") + ", " + count_of(w.scene().steps, "step"));
}

}  // namespace

void bind_world(py::module_& m) {
  py::class_<caliber::World>(m, "World", "A scene file's objects, poses and broad phase.")
      .def(py::init([](const py::object& path) {
             caliber::Scene scene = caliber::load_scene(file_path(path));
             py::gil_scoped_release release;
             return std::make_unique<caliber::World>(std::move(scene));
           }),
           py::arg("path"))
      .def_property_readonly("steps", [](const caliber::World& w) { return w.scene().steps; })
      .def_property_readonly("objects",
                             [](const caliber::World& w) {
                               std::vector<std::string> names;
                               for (const caliber::SceneObject& o : w.scene().objects) names.push_back(o.name);
                               return names;
                             })
      .def(
          "step",
          [](const caliber::World& world, caliber::Engine& engine, int k) {
            caliber::StepResult s;
            {
              py::gil_scoped_release release;
              s = caliber::step(world, engine, k);
            }
            return to_result(std::move(s.contacts), s.stats, s.limit_reached, world.scene().query.kind);
          },
          py::arg("engine"), py::arg("k"), "Step k: poses and broad phase, then the engine.")
      .def(
          "sweep",
          [](const caliber::World& world, caliber::Engine& engine, int k, double tolerance, std::uint64_t max_queries) {
            const caliber::SweepRequest request = sweep_request(tolerance, max_queries);
            std::vector<caliber::PairSweep> swept;
            {
              py::gil_scoped_release release;
              swept = world.sweep(k, engine, request);
            }
            return swept_pairs(swept);
          },
          py::arg("engine"), py::arg("k"), py::kw_only(), py::arg("tolerance") = 0.0, py::arg("max_queries") = 100000,
          "The pairs that touch between step k and k + 1, following the scene's motions (cut where an object turns more "
          "than a quarter turn or has keys), with the scene's groups: [((a, b), Sweep)], times as fractions of the step.")
      .def("__repr__", repr_of<caliber::World>("World", &world_repr))
      .def("__reduce__", [](const caliber::World&) -> py::object {
        throw not_picklable("World", "load the scene file again where it is needed");
      });
}

}  // namespace caliber_python
