// The `haze` Python module (docs/PYTHON.md): pybind11 bindings over the same API. Scenes from
// dicts or files, numpy densities viewed in place where their layout allows, images and fields out
// as numpy arrays, solutions with update, progress and cancellation, haze.Error.
#include <haze/all.h>
#include <haze/core/error.h>
#include <haze/core/image.h>
#include <haze/core/method.h>
#include <haze/core/scene.h>
#include <haze/particles/field.h>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>

namespace py = pybind11;

namespace haze::python {
namespace {

// JSON through Python's own json module: dicts, lists, numbers and strings as a scene file has them.
nlohmann::json to_json(const py::handle& object) {
  const std::string text = py::module_::import("json").attr("dumps")(object).cast<std::string>();
  return nlohmann::json::parse(text);
}
py::object to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

// A scene and the numpy array its grid density views (None when it views none): held while the
// scene views it, dropped when set_density or set_particles replaces the density.
struct PyScene {
  Scene scene;
  py::object density;
};

// (height, width, 3) float32, rows top to bottom.
py::array_t<float> image_array(const Image& image) {
  py::array_t<float> out({image.height(), image.width(), 3});
  std::copy(image.data().begin(), image.data().end(), out.mutable_data());
  return out;
}

py::dict result_dict(const RenderResult& r) {
  py::dict d;
  d["radiance"] = image_array(r.radiance);
  if (r.std_error) d["std_error"] = image_array(*r.std_error);
  if (r.inscatter) {
    d["inscatter"] = image_array(*r.inscatter);
    d["transmittance"] = image_array(*r.transmittance);
    d["surface"] = image_array(*r.surface);
  }
  d["stats"] = to_python(r.stats);
  return d;
}

// A Python callable fraction -> bool (or None: go on) as a ProgressCallback, called with the GIL
// held from whichever worker thread reports; an exception in it cancels the work.
ProgressCallback progress_callback(const std::optional<py::function>& progress) {
  if (!progress) return {};
  auto function = std::make_shared<py::function>(*progress);
  return [function](double fraction) {
    py::gil_scoped_acquire gil;
    try {
      const py::object go_on = (*function)(fraction);
      return go_on.is_none() || go_on.cast<bool>();
    } catch (const py::error_already_set&) {
      return false;
    }
  };
}

RenderOptions options_from(const py::object& settings, int threads, const std::optional<py::function>& progress) {
  RenderOptions options;
  options.threads = threads;
  if (!settings.is_none()) options.settings = to_json(settings);
  options.progress = progress_callback(progress);
  return options;
}

// A grid density viewing a C-contiguous float32 (nz, ny, nx) array in place (x fastest), or a copy
// of any other array of that shape.
GridDensity grid_from(const py::array& array, py::object& kept) {
  if (array.ndim() != 3) throw Error("density", to_text(array.ndim()) + " dimensions", "a (nz, ny, nx) array");
  const std::array<int, 3> resolution{static_cast<int>(array.shape(2)), static_cast<int>(array.shape(1)), static_cast<int>(array.shape(0))};
  auto floats = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!floats) throw Error("density", "an array of dtype " + py::str(array.dtype()).cast<std::string>(), "numbers");
  kept = floats;  // the caller's own array when it was float32 and C-contiguous: viewed, not copied
  return GridDensity::viewing(resolution, std::span<const float>(floats.data(), static_cast<size_t>(floats.size())));
}

// A particle medium from numpy arrays (copied: the density's spatial index is built from them),
// keeping the material, grid resolution and emission of `current`, a scene's particles block.
using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
MediumDesc particles_from(const std::optional<MediumDesc>& current, const Floats& positions, const std::optional<Floats>& density,
                          const std::optional<Floats>& diameter) {
  const auto* field = current ? std::get_if<FieldDensity>(&current->density) : nullptr;
  const auto* particles = field ? dynamic_cast<const particles::ParticleDensity*>(field->field.get()) : nullptr;
  if (!particles)
    throw Error("particles", current ? "a medium of density type \"" + (field ? field->type : std::string("other")) + "\"" : "missing",
                "a scene with a particles block (its sigma_t, albedo, phase; \"positions\": [] will do) whose particles to set");
  if (positions.ndim() != 2 || positions.shape(1) != 3)
    throw Error("particles.positions", "an array of shape " + py::str(positions.attr("shape")).cast<std::string>(), "(n, 3)");
  particles::ParticleSet set;
  set.material = particles->set().material;
  const auto n = static_cast<size_t>(positions.shape(0));
  set.positions.resize(n);
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));
  std::copy(positions.data(), positions.data() + 3 * n, reinterpret_cast<float*>(set.positions.data()));
  auto per_particle = [&](const std::optional<Floats>& values, const char* name, std::vector<float>& out) {
    if (!values) return;
    if (values->ndim() != 1) throw Error(std::string("particles.") + name, "an array of shape " + py::str(values->attr("shape")).cast<std::string>(), "(n,)");
    out.assign(values->data(), values->data() + values->size());
  };
  per_particle(density, "density", set.density);
  per_particle(diameter, "diameter", set.diameters);
  particles::validate(set.view());
  MediumDesc medium = particles::particle_medium(std::move(set), field->grid_resolution);
  medium.emission = current->emission;
  return medium;
}

// A solution and the numpy array its scene's grid density views: the scene's at prepare, then the
// last update's (an update with particles views none). Methods that sample the density into a grid
// of their own still keep the solution's scene, which views it (a rebuild reads it again).
struct PySolution {
  std::unique_ptr<Solution> solution;
  py::object density;
};

}  // namespace

PYBIND11_MODULE(haze, m) {
  m.doc() = "Haze: light transport in participating media (docs/PYTHON.md)";
  register_all();

  // haze.Error (a ValueError) with .field, .value and .expected; haze.Cancelled, a haze.Error, when
  // a progress callback stops the work.
  static PyObject* const error = PyErr_NewException("haze.Error", PyExc_ValueError, nullptr);
  static PyObject* const cancelled = PyErr_NewException("haze.Cancelled", error, nullptr);
  m.attr("Error") = py::handle(error);
  m.attr("Cancelled") = py::handle(cancelled);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      PyObject* type = dynamic_cast<const Cancelled*>(&e) ? cancelled : error;
      py::object instance = py::reinterpret_borrow<py::object>(type)(e.what());
      instance.attr("field") = e.field();
      instance.attr("value") = e.value();
      instance.attr("expected") = e.expected();
      PyErr_SetObject(type, instance.ptr());
    }
  });

  py::class_<PyScene, std::shared_ptr<PyScene>>(m, "Scene", "A scene (docs/SCENES.md): camera, medium, lights, surfaces")
      .def_static(
          "from_dict",
          [](const py::object& dict, const std::string& directory) {
            auto s = std::make_shared<PyScene>();
            s->scene = Scene::from_json(to_json(dict), directory);
            return s;
          },
          py::arg("scene"), py::arg("directory") = ".", "A scene from a dict shaped as a scene file; relative file names resolve against directory")
      .def_static(
          "load", [](const std::string& path) { return std::make_shared<PyScene>(PyScene{Scene::load(path), {}}); }, py::arg("path"))
      .def(
          "set_density",
          [](PyScene& s, const py::array& density, const std::optional<std::array<std::array<double, 3>, 2>>& bounds) {
            if (!s.scene.medium) throw Error("medium", "missing", "a medium whose density to set");
            py::object kept;
            MediumDesc medium = *s.scene.medium;
            medium.density = grid_from(density, kept);
            if (bounds) medium.bounds = {Vec3((*bounds)[0][0], (*bounds)[0][1], (*bounds)[0][2]), Vec3((*bounds)[1][0], (*bounds)[1][1], (*bounds)[1][2])};
            check_medium(medium);
            s.scene.medium = medium;
            s.density = kept;  // the array viewed before is no longer held
          },
          py::arg("density"), py::arg("bounds") = std::nullopt,
          "The medium's density from a (nz, ny, nx) array over its bounds: viewed in place when float32 and C-contiguous")
      .def(
          "set_particles",
          [](PyScene& s, const Floats& positions, const std::optional<Floats>& density, const std::optional<Floats>& diameter) {
            s.scene.medium = particles_from(s.scene.medium, positions, density, diameter);
            s.density = py::none();  // particles are copied
          },
          py::arg("positions"), py::arg("density") = std::nullopt, py::arg("diameter") = std::nullopt,
          "The particles of the scene's particles block from arrays: positions (n, 3), density and diameter (n,) (copied)")
      .def_property_readonly("width", [](const PyScene& s) { return s.scene.camera.width_px; })
      .def_property_readonly("height", [](const PyScene& s) { return s.scene.camera.height_px; });

  py::class_<PySolution>(m, "Solution", "A prepared method: render any number of times, update, read fields")
      .def(
          "render",
          [](const PySolution& s, int threads, const std::optional<py::function>& progress) {
            RenderOptions options = options_from(py::none(), threads, progress);
            RenderResult result;
            {
              py::gil_scoped_release release;
              result = s.solution->render(options);
            }
            return result_dict(result);
          },
          py::arg("threads") = 0, py::arg("progress") = std::nullopt)
      .def(
          "update",
          [](PySolution& s, const std::optional<py::array>& density, const std::optional<Floats>& positions,
             const std::optional<Floats>& particle_density, const std::optional<Floats>& diameter, int threads,
             const std::optional<py::function>& progress) {
            SceneChange change;
            py::object kept;
            if (density && positions) throw Error("update", "density and particles", "one of them: a grid density or particles");
            if (density) {
              MediumDesc medium = *s.solution->scene().medium;
              medium.density = grid_from(*density, kept);
              change.medium = medium;
            }
            if (positions) change.medium = particles_from(s.solution->scene().medium, *positions, particle_density, diameter);
            UpdateReport report;
            {
              py::gil_scoped_release release;
              report = s.solution->update(change, options_from(py::none(), threads, progress));
            }
            if (change.medium) s.density = kept;  // the new array (None for particles) replaces the one viewed before
            py::dict d;
            d["rebuilt"] = report.rebuilt;
            d["redone"] = report.redone;
            d["seconds"] = report.seconds;
            d["stats"] = to_python(report.stats);
            return d;
          },
          py::arg("density") = std::nullopt, py::arg("positions") = std::nullopt, py::arg("particle_density") = std::nullopt,
          py::arg("diameter") = std::nullopt, py::arg("threads") = 0, py::arg("progress") = std::nullopt,
          "Applies a new grid density (same shape and bounds) or new particles (positions (n, 3), particle_density and diameter "
          "(n,)) and redoes what they reach")
      .def(
          "fluence",
          [](const PySolution& s, const py::array_t<double, py::array::c_style | py::array::forcecast>& points) {
            if (points.ndim() != 2 || points.shape(1) != 3) throw Error("points", "an array of shape " + py::str(points.attr("shape")).cast<std::string>(), "(n, 3)");
            py::array_t<float> out({points.shape(0), static_cast<py::ssize_t>(3)});
            for (py::ssize_t i = 0; i < points.shape(0); ++i) {
              const Rgb f = s.solution->fluence(Vec3(points.at(i, 0), points.at(i, 1), points.at(i, 2)));
              for (int c = 0; c < 3; ++c) out.mutable_at(i, c) = static_cast<float>(f[c]);
            }
            return out;
          },
          py::arg("points"), "Fluence (W/m^2, RGB) at world points (n, 3)")
      .def_property_readonly("method", [](const PySolution& s) { return s.solution->method(); })
      .def_property_readonly("stats", [](const PySolution& s) { return to_python(s.solution->stats()); });

  m.def(
      "prepare",
      [](const std::shared_ptr<PyScene>& scene, const std::string& method, const py::object& settings, int threads,
         const std::optional<py::function>& progress) {
        RenderOptions options = options_from(settings, threads, progress);
        auto solution = std::make_unique<PySolution>();
        {
          py::gil_scoped_release release;
          solution->solution = std::make_unique<Solution>(prepare(scene->scene, method, options));
        }
        solution->density = scene->density;
        return solution;
      },
      py::arg("scene"), py::arg("method") = "", py::arg("settings") = py::none(), py::arg("threads") = 0, py::arg("progress") = std::nullopt,
      "Prepares a method for the scene (its own method when none is named)");
  m.def(
      "render",
      [](const std::shared_ptr<PyScene>& scene, const std::string& method, const py::object& settings, int threads,
         const std::optional<py::function>& progress) {
        RenderOptions options = options_from(settings, threads, progress);
        RenderResult result;
        {
          py::gil_scoped_release release;
          result = render(scene->scene, method, options);
        }
        return result_dict(result);
      },
      py::arg("scene"), py::arg("method") = "", py::arg("settings") = py::none(), py::arg("threads") = 0, py::arg("progress") = std::nullopt,
      "Prepares and renders the scene's camera: {'radiance': (h, w, 3) float32, 'std_error', 'stats'}");
  auto image_from = [](const py::array_t<float, py::array::c_style | py::array::forcecast>& array) {
    if (array.ndim() != 3 || array.shape(2) != 3) throw Error("image", "an array of " + to_text(array.ndim()) + " dimensions", "(height, width, 3)");
    Image image(static_cast<int>(array.shape(1)), static_cast<int>(array.shape(0)));
    std::copy(array.data(), array.data() + array.size(), image.data().begin());
    return image;
  };
  m.def(
      "write_exr", [image_from](const std::string& path, const py::array& image) { write_exr(path, image_from(image)); }, py::arg("path"),
      py::arg("image"), "Writes a (height, width, 3) image as linear float32 EXR (R, G, B)");
  m.def(
      "write_png", [image_from](const std::string& path, const py::array& image, double exposure) { write_png(path, image_from(image), exposure); },
      py::arg("path"), py::arg("image"), py::arg("exposure") = 1.0, "Writes a (height, width, 3) image as a tone-mapped 8-bit PNG preview");
  m.def(
      "methods", [] {
        std::vector<std::string> names;
        for (const MethodInfo& info : registered_methods()) names.push_back(info.name);
        return names;
      },
      "The registered methods");
}

}  // namespace haze::python
