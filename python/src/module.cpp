// SPDX-License-Identifier: Apache-2.0
// The glintbake Python module (_glintbake, wrapped by the glintbake package): NDF assets with
// vectorised queries over numpy arrays (one call per batch, the GIL released while it runs), and
// the bake entry points, which run the tools' own option parsing (cli::*Main) with progress,
// cancellation and errors routed to Python.
#include <glintbake/runtime/ndf_asset.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/version.h>
#ifdef GLINTBAKE_PYTHON_WITH_BAKE
#include <glintbake/cli/embed.h>
#endif

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace py = pybind11;
namespace rt = glintbake::runtime;

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// glintbake.Error, created at import; raised with exit_code, message_id and status attributes.
PyObject* g_error_type = nullptr;

// The tools' exit code for a runtime status (README, "Exit codes").
int exitCodeOf(rt::RuntimeStatus s) {
  switch (s) {
    case rt::RuntimeStatus::kOk:
      return 0;
    case rt::RuntimeStatus::kInvalidArgument:
      return 1;
    case rt::RuntimeStatus::kIoError:
      return 2;
    case rt::RuntimeStatus::kInvalidAsset:
      return 3;
    case rt::RuntimeStatus::kOutOfMemory:
      return 4;
    case rt::RuntimeStatus::kWrongKind:  // as the tools: an asset of a kind this call cannot use
    case rt::RuntimeStatus::kUnsupportedVersion:
    case rt::RuntimeStatus::kPartialBake:
      return 5;
  }
  return 4;
}

[[noreturn]] void raise(const std::string& message, int exit_code, int message_id, const std::string& status) {
  py::object type = py::reinterpret_borrow<py::object>(g_error_type);
  py::object error = type(message);
  error.attr("exit_code") = exit_code;
  error.attr("message_id") = message_id;
  error.attr("status") = status;
  PyErr_SetObject(g_error_type, error.ptr());
  throw py::error_already_set();
}

// Rows of a batch argument: shape (n, width), or (width,) for one row shared by every query.
struct Rows {
  const double* data = nullptr;
  py::ssize_t count = 0;
  py::ssize_t stride = 0;  // 0: one row broadcast
  const double* row(py::ssize_t i) const { return data + i * stride; }
};

Rows rows(const DoubleArray& a, py::ssize_t width, const char* name) {
  Rows r;
  r.data = a.data();
  if (a.ndim() == 1 && a.shape(0) == width) {
    r.count = 1;
    return r;
  }
  if (a.ndim() == 2 && a.shape(1) == width) {
    r.count = a.shape(0);
    r.stride = width;
    return r;
  }
  throw py::value_error(std::string(name) + " must have shape (n, " + std::to_string(width) + ") or (" +
                        std::to_string(width) + ",)");
}

// The number of queries of two batch arguments (each n or broadcast).
py::ssize_t batchSize(Rows& a, Rows& b) {
  const py::ssize_t n = std::max(a.count, b.count);
  if ((a.count != n && a.count != 1) || (b.count != n && b.count != 1))
    throw py::value_error("batch arguments hold different numbers of rows (" + std::to_string(a.count) + " and " +
                          std::to_string(b.count) + ")");
  if (a.count == 1) a.stride = 0;
  if (b.count == 1) b.stride = 0;
  return n;
}

rt::Footprint footprintOf(const double* f) {
  rt::Footprint fp;
  fp.x = f[0];
  fp.y = f[1];
  fp.sigma = f[2];
  return fp;
}

class Asset {
 public:
  static std::unique_ptr<Asset> open(const std::string& path) {
    auto a = std::make_unique<Asset>();
    rt::OpenError error;
    if (rt::RuntimeStatus s = a->asset_.open(path.c_str(), &error); s != rt::RuntimeStatus::kOk)
      raise(path + ": " + error.message, exitCodeOf(s), error.message_id, rt::statusString(s));
    return a;
  }
  static std::unique_ptr<Asset> fromBytes(const py::bytes& bytes) {
    auto a = std::make_unique<Asset>();
    const std::string data = bytes;
    rt::OpenError error;
    if (rt::RuntimeStatus s = a->asset_.openMemory(data.data(), data.size(), &error); s != rt::RuntimeStatus::kOk)
      raise(error.message, exitCodeOf(s), error.message_id, rt::statusString(s));
    return a;
  }

  const rt::NdfSource& source() const { return *asset_.source(); }
  std::string kind() const { return asset_.kindName(); }
  int kindCode() const { return int(asset_.kind()); }
  std::string metadataText() const { return std::string(asset_.metadataJson(), asset_.metadataSize()); }

  py::dict footprintRange() const {
    const rt::FootprintRange r = source().footprintRange();
    py::dict d;
    d["pyramid_min_sigma"] = r.pyramid_min_sigma;
    d["pyramid_max_sigma"] = r.pyramid_max_sigma;
    d["exact_max_sigma"] = r.exact_max_sigma;
    d["handover_max_sigma"] = r.handover_max_sigma;
    d["clustered_min_sigma"] = r.clustered_min_sigma;
    d["clustered_max_sigma"] = r.clustered_max_sigma;
    return d;
  }

  // One query per row of footprints (n, 3) and of args (n, width), rows of width 1 shared:
  // query(source, footprint, args row, &value) -> status. Returns (n,) with NaN where refused.
  template <typename Query>
  py::array_t<double> batch(const DoubleArray& footprints, const DoubleArray& args, py::ssize_t width, const char* name,
                            Query query) const {
    Rows f = rows(footprints, 3, "footprints"), a = rows(args, width, name);
    const py::ssize_t n = batchSize(f, a);
    py::array_t<double> out(n);
    double* o = out.mutable_data();
    {
      py::gil_scoped_release release;
      const rt::NdfSource& src = source();
      for (py::ssize_t i = 0; i < n; ++i) {
        double v = kNaN;
        o[i] = query(src, footprintOf(f.row(i)), a.row(i), &v) == rt::RuntimeStatus::kOk ? v : kNaN;
      }
    }
    return out;
  }

  py::array_t<double> eval(const DoubleArray& footprints, const DoubleArray& points) const {
    return batch(footprints, points, 2, "s",
                 [](const rt::NdfSource& src, const rt::Footprint& fp, const double* s, double* v) {
                   return src.eval(fp, rt::SPoint{s[0], s[1]}, v);
                 });
  }

  py::array_t<double> pdf(const DoubleArray& footprints, const DoubleArray& points) const {
    return batch(footprints, points, 2, "s",
                 [](const rt::NdfSource& src, const rt::Footprint& fp, const double* s, double* v) {
                   return src.pdf(fp, rt::SPoint{s[0], s[1]}, v);
                 });
  }

  py::array_t<double> average(const DoubleArray& footprints, const DoubleArray& rects) const {
    return batch(footprints, rects, 4, "rects",
                 [](const rt::NdfSource& src, const rt::Footprint& fp, const double* r, double* v) {
                   rt::SRect rect;
                   rect.x0 = r[0];
                   rect.y0 = r[1];
                   rect.x1 = r[2];
                   rect.y1 = r[3];
                   return src.average(fp, rect, v);
                 });
  }

  py::tuple sample(const DoubleArray& footprints, const DoubleArray& u) const {
    Rows f = rows(footprints, 3, "footprints"), uu = rows(u, 2, "u");
    const py::ssize_t n = batchSize(f, uu);
    py::array_t<double> points({n, py::ssize_t(2)});
    py::array_t<double> pdfs(n);
    double* sp = points.mutable_data();
    double* pp = pdfs.mutable_data();
    {
      py::gil_scoped_release release;
      const rt::NdfSource& src = source();
      for (py::ssize_t i = 0; i < n; ++i) {
        rt::NdfSample smp;
        if (src.sample(footprintOf(f.row(i)), uu.row(i)[0], uu.row(i)[1], &smp) == rt::RuntimeStatus::kOk) {
          sp[2 * i] = smp.s.x;
          sp[2 * i + 1] = smp.s.y;
          pp[i] = smp.pdf;
        } else {
          sp[2 * i] = sp[2 * i + 1] = pp[i] = kNaN;
        }
      }
    }
    return py::make_tuple(points, pdfs);
  }

  py::array_t<double> mass(const DoubleArray& footprints) const {
    Rows f = rows(footprints, 3, "footprints");
    py::array_t<double> out(f.count);
    double* o = out.mutable_data();
    {
      py::gil_scoped_release release;
      for (py::ssize_t i = 0; i < f.count; ++i) {
        double v = kNaN;
        o[i] = source().mass(footprintOf(f.row(i)), &v) == rt::RuntimeStatus::kOk ? v : kNaN;
      }
    }
    return out;
  }

  py::array_t<float> image(double x, double y, double sigma) const {
    const py::ssize_t r = source().resolution();
    py::array_t<float> out({r, r});
    rt::RuntimeStatus st;
    {
      py::gil_scoped_release release;
      st = source().image(rt::Footprint{x, y, sigma}, out.mutable_data(), size_t(r * r));
    }
    if (st != rt::RuntimeStatus::kOk)
      raise(std::string("image: ") + rt::statusString(st), exitCodeOf(st), 0, rt::statusString(st));
    return out;
  }

 private:
  rt::NdfAsset asset_;
};

// A cancellation token shared with a running bake (set from any thread, or by a progress callback
// returning False).
struct Cancel {
  std::atomic<bool> flag{false};
};

#ifdef GLINTBAKE_PYTHON_WITH_BAKE
using ToolMain = int (*)(int, char**);

// Runs a tool body with argv, the GIL released; returns (exit code, error message, JSON summary
// text). The progress callback runs with the GIL held; an exception in it cancels the run and is
// raised afterwards.
py::tuple runTool(const std::string& tool, std::vector<std::string> args, py::object progress, Cancel* cancel) {
  ToolMain body = nullptr;
  if (tool == "ndfgen") body = &glintbake::cli::ndfgenMain;
  if (tool == "tensorpack") body = &glintbake::cli::tensorpackMain;
  if (tool == "ltcfit") body = &glintbake::cli::ltcfitMain;
  if (!body) throw py::value_error("no bake entry point named '" + tool + "'");
  args.insert(args.begin(), tool);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  Cancel local;
  Cancel* token = cancel ? cancel : &local;
  glintbake::cli::EmbedHooks hooks;
  hooks.cancel = &token->flag;
  std::unique_ptr<py::error_already_set> callback_error;
  if (!progress.is_none()) {
    hooks.progress = [&](const std::string& label, uint64_t done, uint64_t total) {
      py::gil_scoped_acquire acquire;
      if (callback_error) return;
      try {
        py::object keep_going = progress(label, done, total);
        if (!keep_going.is_none() && !keep_going.cast<bool>()) token->flag = true;
      } catch (py::error_already_set& e) {
        callback_error = std::make_unique<py::error_already_set>(std::move(e));
        token->flag = true;
      }
    };
  }
  int code = 0;
  {
    py::gil_scoped_release release;
    glintbake::cli::EmbedScope scope(&hooks);
    code = body(int(argv.size()) - 1, argv.data());
  }
  if (callback_error) {
    callback_error->restore();
    throw py::error_already_set();
  }
  const bool cancelled = token->flag.load() && code != 0;
  const std::string json = hooks.json.is_null() ? std::string() : hooks.json.dump();
  return py::make_tuple(code, hooks.error, json, cancelled);
}
#endif

}  // namespace

PYBIND11_MODULE(_glintbake, m) {
  m.doc() = "glintbake: queries on baked glinty-appearance assets, and the bake entry points";
  g_error_type = PyErr_NewExceptionWithDoc(
      "glintbake.Error",
      "A glintbake failure. exit_code is the tools' exit code (1 bad arguments, 2 I/O, 3 invalid input, 4 runtime "
      "failure or cancelled, 5 unsupported), message_id the validator's stable id (0 if none), status the runtime "
      "status name.",
      PyExc_RuntimeError, nullptr);
  m.attr("Error") = py::reinterpret_borrow<py::object>(g_error_type);
  m.attr("__version__") = rt::versionString();
  m.attr("has_bake") =
#ifdef GLINTBAKE_PYTHON_WITH_BAKE
      true;
#else
      false;
#endif

  py::class_<Asset>(m, "Asset",
                    "An opened NDF asset (ndf-pyramid, tensor-ndf, glitter). Footprints are rows (x, y, sigma) in "
                    "texels of the source map; s-plane points rows (s_x, s_y). Queries take (n, k) arrays or one "
                    "(k,) row that is shared by every query, and return NaN where a query was refused. Queries are "
                    "thread-safe and release the GIL.")
      .def_static("open", &Asset::open, py::arg("path"), "Opens an asset file; raises glintbake.Error on failure")
      .def_static("from_bytes", &Asset::fromBytes, py::arg("data"), "Opens an asset from its bytes")
      .def_property_readonly("kind", &Asset::kind, "Registry name of the asset kind")
      .def_property_readonly("kind_code", &Asset::kindCode, "Numeric asset kind (formats/SPEC.md)")
      .def_property_readonly(
          "resolution", [](const Asset& a) { return a.source().resolution(); }, "Bins per side R of the NDF images")
      .def_property_readonly(
          "map_size",
          [](const Asset& a) {
            const rt::MapSize s = a.source().mapSize();
            return py::make_tuple(s.width, s.height);
          },
          "(width, height) of the source map in texels")
      .def_property_readonly(
          "wrap",
          [](const Asset& a) {
            switch (a.source().wrap()) {
              case rt::MapWrap::kRepeat:
                return "repeat";
              case rt::MapWrap::kClamp:
                return "clamp";
              case rt::MapWrap::kUnbounded:
                break;
            }
            return "unbounded";
          },
          "How positions outside the map read it: 'repeat' or 'clamp'; 'unbounded' for Wang tiles and tiny "
          "examples, which cover the plane without a period")
      .def_property_readonly("footprint_range", &Asset::footprintRange,
                             "The sigma (texels) each path answers (ndf_source.h, FootprintRange)")
      .def_property_readonly("metadata_text", &Asset::metadataText, "The container's metadata JSON text")
      .def("eval", &Asset::eval, py::arg("footprints"), py::arg("s"),
           "P-NDF density per unit s-plane area at each point: float64 (n,)")
      .def("pdf", &Asset::pdf, py::arg("footprints"), py::arg("s"),
           "Density with which sample() draws each point: float64 (n,)")
      .def("average", &Asset::average, py::arg("footprints"), py::arg("rects"),
           "Mean density over s-plane rectangles, rows (x0, y0, x1, y1): float64 (n,)")
      .def("sample", &Asset::sample, py::arg("footprints"), py::arg("u"),
           "Importance samples from uniform numbers u in [0, 1)^2: (points (n, 2), pdf (n,))")
      .def("mass", &Asset::mass, py::arg("footprints"), "Integral of each footprint's NDF over the s-plane")
      .def("image", &Asset::image, py::arg("x"), py::arg("y"), py::arg("sigma"),
           "The R x R image of the footprint's NDF (row 0 at s_y = +1): float32 (R, R)");

  py::class_<Cancel>(m, "Cancel", "A cancellation token for a bake: cancel() from any thread stops it")
      .def(py::init<>())
      .def("cancel", [](Cancel& c) { c.flag = true; })
      .def_property_readonly("cancelled", [](const Cancel& c) { return c.flag.load(); });

#ifdef GLINTBAKE_PYTHON_WITH_BAKE
  m.def("_run_tool", &runTool, py::arg("tool"), py::arg("args"), py::arg("progress") = py::none(),
        py::arg("cancel") = nullptr);
#endif
}
