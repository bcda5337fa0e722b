#include "viscera/tissue/viscoelastic/constant_q_fit.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <Eigen/Dense>

#include "viscera/common/input_error.hpp"

namespace viscera::tissue {

using common::InputError;

namespace {

constexpr int kSamples = 160;  // log-spaced fitting frequencies over the band

std::vector<double> band_samples(double w1, double w2, int n) {
  if (n == 1) return {std::sqrt(w1 * w2)};
  std::vector<double> w(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) w[static_cast<std::size_t>(k)] = w1 * std::pow(w2 / w1, k / double(n - 1));
  return w;
}

// Parameters p = (log w_1..L, log y_1..L) in the relaxed normalisation
// M(w) / M_R = 1 + sum_l y_l i w / (w_l + i w), where any y_l > 0 is a valid material
// (Y_l = y_l / (1 + sum y)). Residuals: Q_target / Q(w_k) - 1, the relative error of 1/Q.
Eigen::VectorXd residuals(const Eigen::VectorXd& p, int L, const std::vector<double>& w, double q) {
  Eigen::VectorXd r(static_cast<Eigen::Index>(w.size()));
  for (std::size_t k = 0; k < w.size(); ++k) {
    double re = 1.0, im = 0.0;
    for (int l = 0; l < L; ++l) {
      const double wl = std::exp(p(l)), y = std::exp(p(L + l)), d = wl * wl + w[k] * w[k];
      re += y * w[k] * w[k] / d;
      im += y * w[k] * wl / d;
    }
    r(static_cast<Eigen::Index>(k)) = q * im / re - 1.0;
  }
  return r;
}

// Weighted Levenberg-Marquardt on the chosen parameters (free = first `n_free` of p are fixed
// when optimise is false: only the weights move).
Eigen::VectorXd levenberg_marquardt(Eigen::VectorXd p, int L, const std::vector<double>& w, double q, const Eigen::VectorXd& weights,
                                    bool move_frequencies, int iterations) {
  const Eigen::Index n = p.size();
  double lambda = 1e-3;
  auto cost = [&](const Eigen::VectorXd& x) { return (weights.array() * residuals(x, L, w, q).array()).matrix().squaredNorm(); };
  double c = cost(p);
  for (int it = 0; it < iterations; ++it) {
    const Eigen::VectorXd r = weights.array() * residuals(p, L, w, q).array();
    Eigen::MatrixXd J(r.size(), n);
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!move_frequencies && j < L) {
        J.col(j).setZero();
        continue;
      }
      Eigen::VectorXd pp = p;
      const double h = 1e-6;
      pp(j) += h;
      J.col(j) = ((weights.array() * residuals(pp, L, w, q).array()).matrix() - r) / h;
    }
    const Eigen::MatrixXd A = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      Eigen::MatrixXd Ad = A;
      Ad.diagonal() += lambda * (A.diagonal().array() + 1e-12).matrix();
      const Eigen::VectorXd step = Ad.ldlt().solve(-g);
      const Eigen::VectorXd trial = p + step;
      const double ct = cost(trial);
      if (std::isfinite(ct) && ct < c) {
        p = trial;
        c = ct;
        lambda = std::max(lambda / 3, 1e-12);
        improved = true;
      } else {
        lambda *= 4;
      }
    }
    if (!improved) break;
  }
  return p;
}

}  // namespace

ConstantQFit fit_constant_q(const ConstantQTarget& t, const std::string& source) {
  const auto bad = [&](const char* field, double v, const char* why) {
    std::ostringstream s;
    s << v << " " << why;
    throw InputError(source, 0, field, s.str());
  };
  if (!(t.q > 0) || !std::isfinite(t.q)) bad("q", t.q, "must be a positive number");
  if (!(t.band_low_hz > 0)) bad("band_low_hz", t.band_low_hz, "must be positive");
  if (!(t.band_high_hz > t.band_low_hz) || !std::isfinite(t.band_high_hz)) bad("band_high_hz", t.band_high_hz, "must be above band_low_hz");
  if (t.mechanisms < 1 || t.mechanisms > 8) bad("mechanisms", t.mechanisms, "must be 1 to 8");
  if (!(t.modulus_pa > 0) || !std::isfinite(t.modulus_pa)) bad("modulus_pa", t.modulus_pa, "must be positive");
  if (!(t.reference_frequency_hz > 0)) bad("reference_frequency_hz", t.reference_frequency_hz, "must be positive");

  const int L = t.fixed_frequencies_rad_s.empty() ? t.mechanisms : static_cast<int>(t.fixed_frequencies_rad_s.size());
  const bool move = t.optimise_frequencies && t.fixed_frequencies_rad_s.empty();
  const double w1 = 2 * M_PI * t.band_low_hz, w2 = 2 * M_PI * t.band_high_hz;
  const std::vector<double> w = band_samples(w1, w2, kSamples);

  // Start: log-spaced frequencies, weights from the linearised least squares of
  // 1/Q ~ sum Y_l w_l w / (w_l^2 + w^2) at 2L-1 frequencies (SeisSol's fitAttenuation).
  Eigen::VectorXd p(2 * L);
  for (int l = 0; l < L; ++l)
    p(l) = !t.fixed_frequencies_rad_s.empty() ? std::log(t.fixed_frequencies_rad_s[static_cast<std::size_t>(l)])
                                              : std::log(L == 1 ? std::sqrt(w1 * w2) : w1 * std::pow(w2 / w1, l / double(L - 1)));
  {
    const std::vector<double> wk = band_samples(w1, w2, 2 * L - 1);
    Eigen::MatrixXd A(static_cast<Eigen::Index>(wk.size()), L);
    Eigen::VectorXd b = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(wk.size()), 1.0 / t.q);
    for (std::size_t k = 0; k < wk.size(); ++k)
      for (int l = 0; l < L; ++l) {
        const double wl = std::exp(p(l));
        A(static_cast<Eigen::Index>(k), l) = wl * wk[k] / (wl * wl + wk[k] * wk[k]);
      }
    const Eigen::VectorXd y = A.colPivHouseholderQr().solve(b);
    for (int l = 0; l < L; ++l) p(L + l) = std::log(std::max(y(l), 1e-6));
  }
  // Least squares, then Lawson-type reweighting towards the minimax (equi-ripple) solution.
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(w.size()));
  p = levenberg_marquardt(p, L, w, t.q, weights, move, 200);
  Eigen::VectorXd best = p;
  double best_err = residuals(p, L, w, t.q).cwiseAbs().maxCoeff();
  for (int round = 0; round < 40; ++round) {
    const Eigen::VectorXd r = residuals(p, L, w, t.q).cwiseAbs();
    weights = (weights.array() * (r.array() + 1e-3 * r.maxCoeff()).sqrt()).matrix();
    weights /= weights.maxCoeff();
    p = levenberg_marquardt(p, L, w, t.q, weights, move, 60);
    const double err = residuals(p, L, w, t.q).cwiseAbs().maxCoeff();
    if (err < best_err) {
      best_err = err;
      best = p;
    }
  }
  p = best;

  ConstantQFit fit;
  fit.solids.unrelaxed_modulus_pa = 1.0;
  double sum_y = 0.0;
  for (int l = 0; l < L; ++l) sum_y += std::exp(p(L + l));
  for (int l = 0; l < L; ++l) {
    fit.solids.omega_rad_s.push_back(std::exp(p(l)));
    fit.solids.weight.push_back(std::exp(p(L + l)) / (1.0 + sum_y));
  }
  // Scale M_U so that |M| matches the target at the reference frequency.
  fit.solids.unrelaxed_modulus_pa = t.modulus_pa / std::abs(fit.solids.complex_modulus(2 * M_PI * t.reference_frequency_hz));
  fit.q_min = 1e300;
  fit.q_max = -1e300;
  for (double wk : band_samples(w1, w2, 2000)) {
    const double qk = fit.solids.q(wk);
    fit.q_min = std::min(fit.q_min, qk);
    fit.q_max = std::max(fit.q_max, qk);
  }
  fit.max_relative_error = std::max(std::abs(fit.q_min / t.q - 1), std::abs(fit.q_max / t.q - 1));
  return fit;
}

std::string describe(const ConstantQFit& fit, const ConstantQTarget& t) {
  std::ostringstream s;
  char line[200];
  std::snprintf(line, sizeof line, "constant Q = %g over %g-%g Hz with %d standard linear solids; |M(%g Hz)| = %g Pa\n", t.q, t.band_low_hz,
                t.band_high_hz, t.mechanisms, t.reference_frequency_hz, t.modulus_pa);
  s << line;
  s << "  mechanism  relaxation frequency [Hz]  relaxation time [s]  weight Y\n";
  for (std::size_t l = 0; l < fit.solids.size(); ++l) {
    std::snprintf(line, sizeof line, "  %9zu  %25.5g  %19.5g  %8.5f\n", l + 1, fit.solids.omega_rad_s[l] / (2 * M_PI),
                  1.0 / fit.solids.omega_rad_s[l], fit.solids.weight[l]);
    s << line;
  }
  std::snprintf(line, sizeof line, "  unrelaxed modulus %.5g Pa, relaxed modulus %.5g Pa; achieved Q over the band %.3f..%.3f (%+.1f%% / %+.1f%%)\n",
                fit.solids.unrelaxed_modulus_pa, fit.solids.relaxed_modulus(), fit.q_min, fit.q_max, 100 * (fit.q_min / t.q - 1),
                100 * (fit.q_max / t.q - 1));
  s << line;
  return s.str();
}

}  // namespace viscera::tissue
