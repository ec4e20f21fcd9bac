// glintquery: answers P-NDF queries on a baked NDF asset (ndf-pyramid or tensor-ndf) through the
// runtime-lite, exactly as a renderer would see them: point values, the blended image of a
// footprint, and JSON-lines batches of point, range, sample, pdf and mass queries.
#include <glintbake/bake/io/image_io.h>
#include <glintbake/cli/runtime_status.h>
#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_source.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace cli = glintbake::cli;
namespace rt = glintbake::runtime;
using cli::Error;
using cli::Json;

// Parses "A,B" into two finite numbers.
void parsePair(const std::string& text, const char* option, double* a, double* b) {
  const size_t comma = text.find(',');
  bool ok = comma != std::string::npos;
  if (ok) {
    try {
      size_t ua = 0, ub = 0;
      const std::string sa = text.substr(0, comma), sb = text.substr(comma + 1);
      *a = std::stod(sa, &ua);
      *b = std::stod(sb, &ub);
      ok = ua == sa.size() && ub == sb.size() && std::isfinite(*a) && std::isfinite(*b);
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok) throw Error(cli::kExitBadArguments, std::string(option) + " expects two numbers A,B (got '" + text + "')");
}

// An opened NDF asset of any kind the runtime reads.
struct Asset {
  std::unique_ptr<rt::NdfSource> source;
  std::string kind;  // "ndf-pyramid", "tensor-ndf"
};

Asset openAsset(cli::Tool& tool, const std::string& path) {
  tool.addInput(path);
  Asset asset;
  const rt::Status s = rt::openNdfAsset(path.c_str(), &asset.source);
  if (s == rt::Status::kOk) {
    asset.kind = glintbake::format::assetKindString(asset.source->kind());
    return asset;
  }
  throw Error(cli::exitCodeOfRuntime(s), "cannot open " + path + ": " + rt::statusString(s));
}

void check(rt::Status s, const char* what) {
  if (s != rt::Status::kOk) throw Error(cli::kExitBadArguments, std::string(what) + ": " + rt::statusString(s));
}

double number(const Json& line, const char* key) {
  auto it = line.find(key);
  if (it == line.end() || !it->is_number()) throw std::invalid_argument(std::string("missing number '") + key + "'");
  return it->get<double>();
}

std::vector<double> numbers(const Json& line, const char* key, size_t n) {
  auto it = line.find(key);
  if (it == line.end() || !it->is_array() || it->size() != n)
    throw std::invalid_argument(std::string("'") + key + "' must be an array of " + std::to_string(n) + " numbers");
  std::vector<double> v;
  for (const auto& e : *it) {
    if (!e.is_number()) throw std::invalid_argument(std::string("'") + key + "' must hold numbers");
    v.push_back(e.get<double>());
  }
  return v;
}

// Answers one batch query; throws std::invalid_argument on a malformed query.
//   point  "s": [sx, sy]                    -> "value" (density per unit s-plane area)
//   pdf    "s": [sx, sy]                    -> "pdf" (density of sample(); "value" repeats it)
//   range  "s0": [x0, y0], "s1": [x1, y1]   -> "average" over the rectangle with corners s0 < s1
//          (or "rect": [x0, y0, x1, y1];       "value" repeats it)
//   sample "u": [u1, u2] in [0, 1)          -> "s", "pdf"
//   mass                                    -> "mass" (integral over the s-plane)
Json answer(const rt::NdfSource& ndf, const Json& q) {
  if (!q.is_object()) throw std::invalid_argument("a query must be a JSON object");
  auto op_it = q.find("op");
  if (op_it == q.end() || !op_it->is_string()) throw std::invalid_argument("missing string 'op'");
  const std::string op = op_it->get<std::string>();
  rt::Footprint fp;
  fp.x = number(q, "x");
  fp.y = number(q, "y");
  fp.sigma = number(q, "sigma");
  Json out;
  out["op"] = op;
  if (q.contains("id")) out["id"] = q["id"];
  auto fail = [](rt::Status s) { throw std::invalid_argument(rt::statusString(s)); };
  if (op == "point" || op == "pdf") {
    const std::vector<double> s = numbers(q, "s", 2);
    double v = 0.0;
    const rt::Status st =
        op == "point" ? ndf.eval(fp, rt::SPoint{s[0], s[1]}, &v) : ndf.pdf(fp, rt::SPoint{s[0], s[1]}, &v);
    if (st != rt::Status::kOk) fail(st);
    if (op == "pdf") out["pdf"] = v;
    out["value"] = v;
  } else if (op == "range") {
    rt::SRect rect;
    if (q.contains("rect")) {
      const std::vector<double> r = numbers(q, "rect", 4);
      rect.x0 = r[0];
      rect.y0 = r[1];
      rect.x1 = r[2];
      rect.y1 = r[3];
    } else {
      const std::vector<double> s0 = numbers(q, "s0", 2), s1 = numbers(q, "s1", 2);
      rect.x0 = s0[0];
      rect.y0 = s0[1];
      rect.x1 = s1[0];
      rect.y1 = s1[1];
    }
    if (!(rect.x1 > rect.x0 && rect.y1 > rect.y0))
      throw std::invalid_argument("a range needs s0 < s1 in both coordinates");
    double v = 0.0;
    if (rt::Status st = ndf.average(fp, rect, &v); st != rt::Status::kOk) fail(st);
    out["average"] = v;
    out["value"] = v;
  } else if (op == "sample") {
    const std::vector<double> u = numbers(q, "u", 2);
    if (!(u[0] >= 0.0 && u[0] < 1.0 && u[1] >= 0.0 && u[1] < 1.0))
      throw std::invalid_argument("'u' must hold two numbers in [0, 1)");
    rt::NdfSample smp;
    if (rt::Status st = ndf.sample(fp, u[0], u[1], &smp); st != rt::Status::kOk) {
      if (st == rt::Status::kInvalidArgument) throw std::invalid_argument("the footprint's NDF has no mass to sample");
      fail(st);
    }
    out["s"] = {smp.s.x, smp.s.y};
    out["pdf"] = smp.pdf;
  } else if (op == "mass") {
    double v = 0.0;
    if (rt::Status st = ndf.mass(fp, &v); st != rt::Status::kOk) fail(st);
    out["mass"] = v;
  } else {
    throw std::invalid_argument("unknown op '" + op + "' (point, range, sample, pdf, mass)");
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Tool tool("glintquery",
                 "Queries baked NDF assets (ndf-pyramid, tensor-ndf) through the runtime (point, image, batch)");
  CLI::App& app = tool.app();
  app.require_subcommand(1);
  app.fallthrough();
  std::string asset, at_text, s_text, output;
  double sigma = 1.0;
  double png_scale = 0.0;

  CLI::App* point = app.add_subcommand("point", "P-NDF value at one s-plane point");
  point->add_option("asset", asset, "NDF asset (.gbk)")->required();
  point->add_option("--at", at_text, "Footprint centre X,Y in texels")->required();
  point->add_option("--sigma", sigma, "Footprint std in texels (>= 0)")->required();
  point->add_option("--s", s_text, "s-plane point SX,SY")->required();

  CLI::App* image = app.add_subcommand("image", "The blended NDF image the runtime sees (EXR: densities, PNG: scaled)");
  image->add_option("asset", asset, "NDF asset (.gbk)")->required();
  image->add_option("--at", at_text, "Footprint centre X,Y in texels")->required();
  image->add_option("--sigma", sigma, "Footprint std in texels (>= 0)")->required();
  image->add_option("-o,--output", output, "Output image (.exr, .png, ...)")->required();
  image->add_option("--scale", png_scale,
                    "Multiply densities by this before writing (default: 1 for float "
                    "formats, 1/max for integer formats)");

  CLI::App* batch = app.add_subcommand(
      "batch",
      "JSON-lines queries on stdin, one JSON line per answer on stdout. Each query: {\"op\", \"x\", \"y\", "
      "\"sigma\", optional \"id\"} plus per op: point/pdf \"s\":[sx,sy]; range \"s0\":[x0,y0], \"s1\":[x1,y1]; "
      "sample \"u\":[u1,u2]; mass (schemas/glintquery-batch.schema.json)");
  batch->add_option("asset", asset, "NDF asset (.gbk)")->required();

  return tool.run(argc, argv, [&](cli::Tool& t) {
    if (*point) {
      double x, y, sx, sy;
      parsePair(at_text, "--at", &x, &y);
      parsePair(s_text, "--s", &sx, &sy);
      if (!(sigma >= 0.0) || !std::isfinite(sigma)) throw Error(cli::kExitBadArguments, "--sigma must be >= 0");
      const Asset ndf = openAsset(t, asset);
      rt::Footprint fp;
      fp.x = x;
      fp.y = y;
      fp.sigma = sigma;
      double v = 0.0;
      check(ndf.source->eval(fp, rt::SPoint{sx, sy}, &v), "point query");
      if (t.common().json) {
        Json doc;
        doc["tool"] = "glintquery";
        doc["op"] = "point";
        doc["asset"] = cli::baseName(asset);
        doc["kind"] = ndf.kind;
        doc["at"] = {x, y};
        doc["sigma"] = sigma;
        doc["s"] = {sx, sy};
        doc["value"] = v;
        t.printJson(doc);
      } else {
        std::ostringstream os;
        os.precision(9);
        os << v << "\n";
        std::cout << os.str();
      }
      return cli::kExitOk;
    }
    if (*image) {
      double x, y;
      parsePair(at_text, "--at", &x, &y);
      if (!(sigma >= 0.0) || !std::isfinite(sigma)) throw Error(cli::kExitBadArguments, "--sigma must be >= 0");
      if (!(png_scale >= 0.0) || !std::isfinite(png_scale)) throw Error(cli::kExitBadArguments, "--scale must be >= 0");
      const Asset ndf = openAsset(t, asset);
      rt::Footprint fp;
      fp.x = x;
      fp.y = y;
      fp.sigma = sigma;
      const int res = ndf.source->resolution();
      std::vector<float> pixels(size_t(res) * size_t(res));
      check(ndf.source->image(fp, pixels.data(), pixels.size()), "image query");
      double mass = 0.0, peak = 0.0;
      for (float v : pixels) {
        mass += v;
        peak = std::max(peak, double(v));
      }
      mass *= 4.0 / (double(res) * res);
      std::string ext =
          output.substr(output.find_last_of('.') == std::string::npos ? output.size() : output.find_last_of('.'));
      for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
      const bool float_format = ext == ".exr" || ext == ".hdr" || ext == ".pfm";
      double scale = png_scale > 0.0 ? png_scale : (float_format ? 1.0 : (peak > 0.0 ? 1.0 / peak : 1.0));
      if (scale != 1.0)
        for (float& v : pixels) v = float(v * scale);
      if (glintbake::bake::Status st = glintbake::bake::writeImage(output, res, res, 1, pixels.data()); !st) {
        throw Error(int(st.error().code), st.error().message);
      }
      t.addOutput(output);
      if (t.common().json) {
        Json doc;
        doc["tool"] = "glintquery";
        doc["op"] = "image";
        doc["asset"] = cli::baseName(asset);
        doc["kind"] = ndf.kind;
        doc["output"] = cli::baseName(output);
        doc["at"] = {x, y};
        doc["sigma"] = sigma;
        doc["resolution"] = res;
        doc["mass"] = mass;
        doc["max"] = peak;
        doc["scale"] = scale;
        t.printJson(doc);
      } else {
        t.info("wrote " + output + " (" + std::to_string(res) + "x" + std::to_string(res) + ", mass " +
               std::to_string(mass) + ")");
      }
      return cli::kExitOk;
    }
    // batch
    const Asset ndf = openAsset(t, asset);
    std::string line;
    uint64_t count = 0, failed = 0;
    std::string first_error;
    while (std::getline(std::cin, line)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      ++count;
      Json out;
      try {
        out = answer(*ndf.source, Json::parse(line));
      } catch (const std::exception& e) {
        ++failed;
        const std::string msg = std::string("query ") + std::to_string(count) + ": " + e.what();
        if (first_error.empty()) first_error = msg;
        out = Json::object();
        out["error"] = msg;
      }
      std::cout << out.dump() << "\n";
    }
    std::cout.flush();
    if (failed > 0) {
      throw Error(cli::kExitInvalidInput, std::to_string(failed) + " of " + std::to_string(count) +
                                              " queries failed (first: " + first_error + ")");
    }
    return cli::kExitOk;
  });
}
