// SPDX-License-Identifier: Apache-2.0
// The published two-texture layout of LTC tables, the sphere table, and the table error measure.
#include <glintbake/bake/ltc/table.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace glintbake::bake::ltc {

namespace {

// Cosine-weighted solid angle of a spherical cap of half-angle s whose axis makes angle w with the
// normal, clipped to the upper hemisphere (Snyder 1996, "Area light sources for real-time
// graphics", the I_hemi form used by Heitz et al.'s sphere table).
double capProjectedSolidAngle(double w, double s) {
  const double sin_s2 = std::sin(s) * std::sin(s);
  const double half_pi = 0.5 * kPi;
  if (w <= half_pi - s) return kPi * std::cos(w) * sin_s2;
  if (w >= half_pi + s) return 0.0;
  const double g = std::asin(std::clamp(std::cos(s) / std::sin(w), -1.0, 1.0));
  const double cos_g = std::cos(g);
  const double big_g = -2.0 * std::sin(w) * std::cos(s) * cos_g + half_pi - g + std::sin(g) * cos_g;
  const double big_h = std::cos(w) * (cos_g * std::sqrt(std::max(0.0, sin_s2 - cos_g * cos_g)) +
                                      sin_s2 * std::asin(std::clamp(cos_g / std::sin(s), -1.0, 1.0)));
  if (w < half_pi) return kPi * std::cos(w) * sin_s2 + big_g - big_h;
  return big_g + big_h;
}

}  // namespace

std::vector<float> sphereTable(int size) {
  std::vector<float> out(size_t(size) * size_t(size));
  for (int j = 0; j < size; ++j) {
    for (int i = 0; i < size; ++i) {
      const double z = 2.0 * i / (size - 1) - 1.0;
      const double len = double(j) / (size - 1);
      const double sigma = std::asin(std::sqrt(len));
      const double omega = std::acos(z);
      const double value = sigma > 0.0 ? capProjectedSolidAngle(omega, sigma) / (kPi * len) : std::max(z, 0.0);
      out[size_t(i) + size_t(size) * size_t(j)] = float(value);
    }
  }
  return out;
}

PublishedTable packPublished(const FittedTable& table) {
  const int n = table.size;
  PublishedTable out;
  out.size = n;
  out.ltc1.assign(size_t(n) * n * 4, 0.0f);
  out.ltc2.assign(size_t(n) * n * 4, 0.0f);
  const std::vector<float> sphere = sphereTable(n);
  for (size_t i = 0; i < size_t(n) * n; ++i) {
    const FittedCell& cell = table.cells[i];
    Mat3 inv = inverse(cell.m);
    const double middle = inv.m[1][1];
    for (auto& row : inv.m)
      for (double& e : row) e /= middle;
    out.ltc1[4 * i + 0] = float(inv.m[0][0]);
    out.ltc1[4 * i + 1] = float(inv.m[2][0]);
    out.ltc1[4 * i + 2] = float(inv.m[0][2]);
    out.ltc1[4 * i + 3] = float(inv.m[2][2]);
    out.ltc2[4 * i + 0] = float(cell.norm);
    out.ltc2[4 * i + 1] = float(cell.fresnel);
    out.ltc2[4 * i + 2] = 0.0f;
    out.ltc2[4 * i + 3] = sphere[i];
  }
  return out;
}

Ltc ltcFromPublished(const PublishedTable& table, int a, int t) {
  const float* p = &table.ltc1[(size_t(a) + size_t(table.size) * size_t(t)) * 4];
  Mat3 inv;
  inv.m[0][0] = p[0], inv.m[0][1] = 0.0, inv.m[0][2] = p[2];
  inv.m[1][0] = 0.0, inv.m[1][1] = 1.0, inv.m[1][2] = 0.0;
  inv.m[2][0] = p[1], inv.m[2][1] = 0.0, inv.m[2][2] = p[3];
  const double norm = table.ltc2[(size_t(a) + size_t(table.size) * size_t(t)) * 4];
  return Ltc::fromInverse(inv, norm);
}

CellError cellError(BrdfKind brdf, const Ltc& ltc, Vec3 v, double alpha, int samples) {
  double objective = 0.0, l1 = 0.0;
  for (int j = 0; j < samples; ++j) {
    for (int i = 0; i < samples; ++i) {
      const double u1 = (i + 0.5) / samples;
      const double u2 = (j + 0.5) / samples;
      for (int strategy = 0; strategy < 2; ++strategy) {
        const Vec3 l = strategy == 0 ? ltc.sample(u1, u2) : sampleBrdf(brdf, v, alpha, u1, u2);
        double pdf_brdf = 0.0;
        const double f_brdf = evalBrdf(brdf, v, l, alpha, &pdf_brdf);
        const double f_ltc = ltc.eval(l);
        const double pdf_ltc = ltc.magnitude > 0.0 ? f_ltc / ltc.magnitude : 0.0;
        const double diff = std::abs(f_brdf - f_ltc);
        const double denom = pdf_ltc + pdf_brdf;
        if (denom > 0.0 && std::isfinite(diff)) {
          objective += diff * diff * diff / denom;
          l1 += diff / denom;
        }
      }
    }
  }
  const double n = double(samples) * samples;
  CellError error;
  error.objective = objective / n;
  error.relative_l1 = ltc.magnitude > 0.0 ? l1 / n / ltc.magnitude : 0.0;
  return error;
}

Result<TableError> evaluateTable(const PublishedTable& table, BrdfKind brdf, int samples) {
  const int n = table.size;
  if (n < 2 || table.ltc1.size() != size_t(n) * n * 4 || table.ltc2.size() != size_t(n) * n * 4)
    return makeError(ErrorCode::kInvalidInput, "table arrays do not match their size");
  if (samples < 4 || samples > 4096) return makeError(ErrorCode::kBadArgument, "samples must be in [4, 4096]");
  for (float value : table.ltc1)
    if (!std::isfinite(value)) return makeError(ErrorCode::kInvalidInput, "table holds non-finite values");
  for (float value : table.ltc2)
    if (!std::isfinite(value)) return makeError(ErrorCode::kInvalidInput, "table holds non-finite values");
  TableError result;
  result.size = n;
  result.samples = samples;
  result.cells.assign(size_t(n) * n, CellError{});
  tbb::parallel_for(0, n * n, [&](int index) {
    const int a = index % n;
    const int t = index / n;
    const Ltc ltc = ltcFromPublished(table, a, t);
    result.cells[size_t(index)] = cellError(brdf, ltc, cellView(t, n), cellAlpha(a, n), samples);
  });
  // Serial reductions in index order: identical for every thread count.
  double sum_l1 = 0.0, sum_objective = 0.0, sum_log = 0.0;
  int positive = 0;
  for (size_t i = 0; i < result.cells.size(); ++i) {
    const CellError& cell = result.cells[i];
    sum_l1 += cell.relative_l1;
    sum_objective += cell.objective;
    if (cell.objective > 0.0) {
      sum_log += std::log10(cell.objective);
      ++positive;
    }
    if (cell.relative_l1 > result.max_relative_l1) {
      result.max_relative_l1 = cell.relative_l1;
      result.max_relative_l1_cell = int(i);
    }
  }
  result.mean_relative_l1 = sum_l1 / double(result.cells.size());
  result.mean_objective = sum_objective / double(result.cells.size());
  result.mean_log10_objective = positive > 0 ? sum_log / positive : 0.0;
  return result;
}

std::string publishedCHeader(const PublishedTable& table, const std::string& guard_comment) {
  std::string out;
  out += "// " + guard_comment + "\n";
  out += "// Linearly transformed cosine tables in the layout of Heitz et al. 2016: N x N cells, flat index\n";
  out += "// a + N t (a: roughness column, t: view-angle row, row t = 0 first). ltc_1 = (m00, m20, m02, m22)\n";
  out += "// of the inverse matrix divided by its middle element; ltc_2 = (norm, fresnel, 0, sphere).\n";
  out += "#pragma once\n\n";
  char line[96];
  std::snprintf(line, sizeof(line), "#define GLINTBAKE_LTC_SIZE %d\n\n", table.size);
  out += line;
  auto emit = [&](const char* name, const std::vector<float>& values) {
    out += "static const float ";
    out += name;
    out += "[GLINTBAKE_LTC_SIZE * GLINTBAKE_LTC_SIZE * 4] = {\n";
    for (size_t i = 0; i < values.size(); i += 4) {
      std::snprintf(line, sizeof(line), "  %.8ef, %.8ef, %.8ef, %.8ef,\n", double(values[i]), double(values[i + 1]),
                    double(values[i + 2]), double(values[i + 3]));
      out += line;
    }
    out += "};\n\n";
  };
  emit("ltc_1", table.ltc1);
  emit("ltc_2", table.ltc2);
  return out;
}

}  // namespace glintbake::bake::ltc
