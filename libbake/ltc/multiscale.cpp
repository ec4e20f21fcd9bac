// SPDX-License-Identifier: Apache-2.0
// Multi-scale LTC roughness (Tao et al. 2021): meso roughness from the mean resultant length, the
// micro/meso combination from a numerical spherical convolution, and Ceres refits of both.
#include <glintbake/bake/ltc/ltc.h>
#include <glintbake/bake/ltc/multiscale.h>

#include <ceres/ceres.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace glintbake::bake::ltc {

namespace {

// Results of fitMultiscale() at its defaults (256 meso points, 9 x 9 combine grid); the unit tests
// refit and check them.
constexpr std::array<double, 5> kMesoFitCoefficients = {0.444866589, 5.452478761, 0.9965650275, 6.451670751,
                                                        -7.375820039};
constexpr std::array<double, 3> kCombineFitCoefficients = {-0.9643196139, 0.107777481, 0.1073185619};

// Composite Simpson rule of |b|'s integrand: accurate where the closed form cancels (alpha ~ 1).
double meanResultantLengthSimpson(double alpha) {
  constexpr int kIntervals = 2048;
  const double a2 = alpha * alpha;
  auto f = [a2](double mu) { return mu * mu / std::sqrt(a2 * (1.0 - mu * mu) + mu * mu); };
  const double h = 1.0 / kIntervals;
  double sum = f(0.0) + f(1.0);
  for (int i = 1; i < kIntervals; ++i) sum += (i % 2 ? 4.0 : 2.0) * f(i * h);
  return 2.0 * sum * h / 3.0;
}

}  // namespace

double meanResultantLength(double alpha) {
  alpha = std::clamp(alpha, 0.0, 1.0);
  if (alpha == 0.0) return 1.0;
  // With a = alpha^2, c = 1 - alpha^2: integral_0^1 mu^2 / sqrt(a + c mu^2) dmu
  // = 1 / (2c) - a / (2 c^1.5) ln((sqrt(c) + 1) / alpha).
  const double a = alpha * alpha;
  const double c = 1.0 - a;
  if (c < 1e-3) return meanResultantLengthSimpson(alpha);
  return 1.0 / c - a / (c * std::sqrt(c)) * std::log((std::sqrt(c) + 1.0) / alpha);
}

double alphaMesoExact(double length) {
  if (!(length < 1.0)) return 0.0;
  if (length <= meanResultantLength(1.0)) return 1.0;
  // |b| decreases monotonically with alpha: bisection.
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (meanResultantLength(mid) > length) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

namespace {

template <typename T>
T mesoRational(const T* c, T y) {
  return y * (c[0] + c[1] * y + c[2] * y * y) / (T(1) + c[3] * y + c[4] * y * y);
}

template <typename T>
T combineForm(const T* k, double a_mi, double a_me) {
  return T(a_mi + a_me) + T(a_mi * a_me) * (k[0] + k[1] * a_mi + k[2] * a_me);
}

}  // namespace

double MesoFit::eval(double length) const {
  if (!(length < 1.0)) return 0.0;
  const double y = std::sqrt(std::max(0.0, 1.0 - length));
  return std::clamp(mesoRational(c.data(), y), 0.0, 1.0);
}

double CombineFit::eval(double alpha_micro, double alpha_meso) const {
  return std::clamp(combineForm(k.data(), alpha_micro, alpha_meso), 0.0, 1.0);
}

double combinePaper(double alpha_micro, double alpha_meso) {
  return 0.07 * alpha_micro * alpha_micro + 0.94 * alpha_micro + alpha_meso - 0.83 * alpha_micro * alpha_meso;
}

namespace {

constexpr int kHistogramBins = 128;

// Density over solid angle of the isotropic LTC diag(alpha, alpha, 1) at normal cosine mu (the
// projected GGX distribution D(m) m.z).
template <typename T>
T isotropicLtcDensity(T alpha, double mu) {
  const T a2 = alpha * alpha;
  const T denom = T(1.0 - mu * mu) + a2 * T(mu * mu);
  return T(mu) * a2 / (T(kPi) * denom * denom);
}

struct HistogramResidual {
  double mu, density, weight;
  template <typename T>
  bool operator()(const T* alpha, T* residual) const {
    residual[0] = T(weight) * (isotropicLtcDensity(alpha[0], mu) - T(density));
    return true;
  }
};

// Cosine of a normal drawn from the isotropic LTC diag(alpha, alpha, 1) given the cosine w_z of
// the underlying clamped-cosine sample.
double ltcNormalCosine(double alpha, double wz) {
  const double s2 = 1.0 - wz * wz;
  return wz / std::sqrt(alpha * alpha * s2 + wz * wz);
}

}  // namespace

double combineNumerical(double alpha_micro, double alpha_meso) {
  alpha_micro = std::clamp(alpha_micro, 0.0, 1.0);
  alpha_meso = std::clamp(alpha_meso, 0.0, 1.0);
  if (alpha_meso == 0.0) return alpha_micro;
  if (alpha_micro == 0.0) return alpha_meso;
  // By symmetry only the meso normal's tilt beta matters: a micro normal m' around n = (sin b, 0,
  // cos b) has world cosine m'.z cos b - m'.x sin b (azimuths are uniform).
  constexpr int kMeso = 512, kMicro = 96;
  std::vector<double> histogram(kHistogramBins, 0.0);
  const double total = double(kMeso) * kMicro * kMicro;
  for (int i = 0; i < kMeso; ++i) {
    const double cos_b = ltcNormalCosine(alpha_meso, std::sqrt((i + 0.5) / kMeso));
    const double sin_b = std::sqrt(std::max(0.0, 1.0 - cos_b * cos_b));
    for (int j = 0; j < kMicro; ++j) {
      const double wz = std::sqrt((j + 0.5) / kMicro);
      const double mz = ltcNormalCosine(alpha_micro, wz);
      const double mr = std::sqrt(std::max(0.0, 1.0 - mz * mz));
      for (int k = 0; k < kMicro; ++k) {
        const double phi = 2.0 * kPi * (k + 0.5) / kMicro;
        const double z = mz * cos_b - mr * std::cos(phi) * sin_b;
        if (z <= 0.0) continue;
        const int bin = std::min(kHistogramBins - 1, int(z * kHistogramBins));
        histogram[size_t(bin)] += 1.0;
      }
    }
  }
  // Density over solid angle: a cosine bin of width 1/B spans 2 pi / B steradians.
  ceres::Problem problem;
  double alpha = std::clamp(alpha_micro + alpha_meso, 0.01, 1.0);
  const double bin_solid_angle = 2.0 * kPi / kHistogramBins;
  for (int b = 0; b < kHistogramBins; ++b) {
    const double mu = (b + 0.5) / kHistogramBins;
    const double density = histogram[size_t(b)] / (total * bin_solid_angle);
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<HistogramResidual, 1, 1>(
                                 new HistogramResidual{mu, density, std::sqrt(bin_solid_angle)}),
                             nullptr, &alpha);
  }
  problem.SetParameterLowerBound(&alpha, 0, 1e-4);
  problem.SetParameterUpperBound(&alpha, 0, 4.0);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.logging_type = ceres::SILENT;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return alpha;
}

namespace {

struct MesoResidual {
  double y, alpha;
  template <typename T>
  bool operator()(const T* c, T* residual) const {
    residual[0] = mesoRational(c, T(y)) - T(alpha);
    return true;
  }
};

struct CombineResidual {
  double a_mi, a_me, alpha;
  template <typename T>
  bool operator()(const T* k, T* residual) const {
    residual[0] = combineForm(k, a_mi, a_me) - T(alpha);
    return true;
  }
};

void solveQuietly(ceres::Problem* problem) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.logging_type = ceres::SILENT;
  options.max_num_iterations = 500;
  options.function_tolerance = 1e-15;
  options.gradient_tolerance = 1e-15;
  options.parameter_tolerance = 1e-15;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
}

void accumulate(FitErrors* errors, double e, int* count) {
  errors->rms += e * e;
  errors->max = std::max(errors->max, std::abs(e));
  ++*count;
}

}  // namespace

MesoFit defaultMesoFit() {
  MesoFit fit;
  fit.c = kMesoFitCoefficients;
  return fit;
}

CombineFit defaultCombineFit() {
  CombineFit fit;
  fit.k = kCombineFitCoefficients;
  return fit;
}

Result<MultiscaleFit> fitMultiscale(int meso_points, int combine_grid) {
  if (meso_points < 8 || meso_points > 100000)
    return makeError(ErrorCode::kBadArgument, "meso points must be in [8, 100000]");
  if (combine_grid < 3 || combine_grid > 64)
    return makeError(ErrorCode::kBadArgument, "combine grid must be in [3, 64]");
  MultiscaleFit fit;
  fit.meso_points = meso_points;
  fit.combine_grid = combine_grid;

  // Meso: samples evenly spaced in alpha, ground truth by the exact |b|(alpha).
  std::vector<std::pair<double, double>> meso;  // (|b|, alpha)
  for (int i = 1; i <= meso_points; ++i) {
    const double alpha = double(i) / meso_points;
    meso.emplace_back(meanResultantLength(alpha), alpha);
  }
  fit.meso.c = {1.0, 0.0, 0.0, 0.0, 0.0};
  {
    ceres::Problem problem;
    for (const auto& [length, alpha] : meso)
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<MesoResidual, 1, 5>(new MesoResidual{std::sqrt(1.0 - length), alpha}),
          nullptr, fit.meso.c.data());
    solveQuietly(&problem);
  }
  int count = 0;
  for (const auto& [length, alpha] : meso) accumulate(&fit.meso_error, fit.meso.eval(length) - alpha, &count);
  fit.meso_error.rms = std::sqrt(fit.meso_error.rms / count);

  // Combine: the numerical convolution on a grid, in parallel into fixed slots.
  const int g = combine_grid;
  std::vector<double> truth(size_t(g) * size_t(g));
  tbb::parallel_for(0, g * g, [&](int index) {
    const double a_mi = double(index % g) / (g - 1);
    const double a_me = double(index / g) / (g - 1);
    truth[size_t(index)] = combineNumerical(a_mi, a_me);
  });
  fit.combine.k = {0.0, 0.0, 0.0};
  {
    ceres::Problem problem;
    for (int index = 0; index < g * g; ++index)
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CombineResidual, 1, 3>(new CombineResidual{
                                   double(index % g) / (g - 1), double(index / g) / (g - 1), truth[size_t(index)]}),
                               nullptr, fit.combine.k.data());
    solveQuietly(&problem);
  }
  int count_ours = 0, count_paper = 0;
  for (int index = 0; index < g * g; ++index) {
    const double a_mi = double(index % g) / (g - 1);
    const double a_me = double(index / g) / (g - 1);
    // Both are compared unclamped-to-truth: the truth itself may exceed 1 for rough inputs.
    accumulate(&fit.combine_error, combineForm(fit.combine.k.data(), a_mi, a_me) - truth[size_t(index)], &count_ours);
    accumulate(&fit.combine_paper_error, combinePaper(a_mi, a_me) - truth[size_t(index)], &count_paper);
  }
  fit.combine_error.rms = std::sqrt(fit.combine_error.rms / count_ours);
  fit.combine_paper_error.rms = std::sqrt(fit.combine_paper_error.rms / count_paper);
  return fit;
}

}  // namespace glintbake::bake::ltc
