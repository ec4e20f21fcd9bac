// SPDX-License-Identifier: Apache-2.0
// glintquery batch: JSON-lines queries on stdin, one JSON answer per line on stdout
// (schemas/glintquery-batch.schema.json).
#include "commands.h"

#include <glintbake/format/json_depth.h>

#include <algorithm>
#include <cstdint>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace glintbake::glintquery {
namespace {

namespace rt = glintbake::runtime;
using cli::Error;
using cli::Json;

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
  auto fail = [](rt::RuntimeStatus s) { throw std::invalid_argument(rt::statusString(s)); };
  if (op == "point" || op == "pdf") {
    const std::vector<double> s = numbers(q, "s", 2);
    double v = 0.0;
    const rt::RuntimeStatus st =
        op == "point" ? ndf.eval(fp, rt::SPoint{s[0], s[1]}, &v) : ndf.pdf(fp, rt::SPoint{s[0], s[1]}, &v);
    if (st != rt::RuntimeStatus::kOk) fail(st);
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
    if (rt::RuntimeStatus st = ndf.average(fp, rect, &v); st != rt::RuntimeStatus::kOk) fail(st);
    out["average"] = v;
    out["value"] = v;
  } else if (op == "sample") {
    const std::vector<double> u = numbers(q, "u", 2);
    if (!(u[0] >= 0.0 && u[0] < 1.0 && u[1] >= 0.0 && u[1] < 1.0))
      throw std::invalid_argument("'u' must hold two numbers in [0, 1)");
    rt::NdfSample smp;
    if (rt::RuntimeStatus st = ndf.sample(fp, u[0], u[1], &smp); st != rt::RuntimeStatus::kOk) {
      if (st == rt::RuntimeStatus::kInvalidArgument)
        throw std::invalid_argument("the footprint's NDF has no mass to sample");
      fail(st);
    }
    out["s"] = {smp.s.x, smp.s.y};
    out["pdf"] = smp.pdf;
  } else if (op == "mass") {
    double v = 0.0;
    if (rt::RuntimeStatus st = ndf.mass(fp, &v); st != rt::RuntimeStatus::kOk) fail(st);
    out["mass"] = v;
  } else {
    throw std::invalid_argument("unknown op '" + op + "' (point, range, sample, pdf, mass)");
  }
  return out;
}

}  // namespace

CLI::App* addBatchCommand(CLI::App& app, BatchOptions& options) {
  CLI::App* batch = app.add_subcommand(
      "batch",
      "JSON-lines queries on stdin, one JSON line per answer on stdout. Each query: {\"op\", \"x\", \"y\", "
      "\"sigma\", optional \"id\"} plus per op: point/pdf \"s\":[sx,sy]; range \"s0\":[x0,y0], \"s1\":[x1,y1]; "
      "sample \"u\":[u1,u2]; mass (schemas/glintquery-batch.schema.json)");
  batch->add_option("asset", options.asset, "NDF asset (.gbk)")->required();
  return batch;
}

int runBatch(cli::Tool& tool, const BatchOptions& options) {
  const Asset ndf = openAsset(tool, options.asset);
  std::string line;
  uint64_t count = 0, failed = 0;
  std::string first_error;
  while (std::getline(std::cin, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    ++count;
    Json out;
    try {
      // nlohmann-json stops at a NUL byte as at the end of the text: refuse it rather than answer
      // the query before it and drop the rest.
      if (const size_t nul = line.find('\0'); nul != std::string::npos)
        throw std::invalid_argument("the line holds a NUL byte at column " + std::to_string(nul + 1));
      if (format::jsonNestingDepth(line) > size_t(format::kMaxJsonDepth))
        throw std::invalid_argument("the line is nested deeper than " + std::to_string(format::kMaxJsonDepth) +
                                    " levels");
      out = answer(*ndf.source, Json::parse(line));
    } catch (const std::exception& e) {
      ++failed;
      const std::string msg = std::string("query ") + std::to_string(count) + ": " + e.what();
      if (first_error.empty()) first_error = msg;
      out = Json::object();
      out["error"] = msg;
    }
    // Invalid UTF-8 (in an echoed id or a message quoting the line) is replaced, not fatal.
    std::cout << out.dump(-1, ' ', false, Json::error_handler_t::replace) << "\n";
  }
  std::cout.flush();
  if (failed > 0) {
    throw Error(cli::kExitInvalidInput, std::to_string(failed) + " of " + std::to_string(count) +
                                            " queries failed (first: " + first_error + ")");
  }
  return cli::kExitOk;
}

}  // namespace glintbake::glintquery
