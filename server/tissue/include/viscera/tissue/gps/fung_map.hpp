#pragma once  // SPDX-License-Identifier: Apache-2.0
// Fung's exponential stiffening of an edge strain e (docs/MODEL.md section 4), in two forms:
//  - the edge map g(e) = (exp(B e) - 1) / B (the published QLV elastic response, applied to each
//    edge: exact in 1D, but in a tetrahedron t = H g is not the gradient of an energy);
//  - the energy map h(e) = e sqrt(phi(B e)), phi(x) = 2 (e^x - 1 - x) / x^2, chosen so that
//    h h' = g: a bar with energy E h(e)^2 / 2 has the same stress E g(e), and a tetrahedron with
//    energy 0.5 h^T H h has tensions t_k = h'(e_k) (H h)_k, a gradient with a symmetric tangent.
// h is smooth and increasing (h' > 0), h(0) = 0, h'(0) = 1, h''(0) = B / 3; B = 0 gives h(e) = e.
// Tension/compression asymmetry in the same form: h scaled by c(e), from sqrt(r) in compression
// to 1 in tension, so that h h' = r g(e) for e << 0 (compressed edges r times as stiff) and g(e)
// for e >> 0. c changes smoothly over a strain of about kAsymmetryWidth around 0 (a kink in h'
// would make Newton cycle on edges at zero strain); the energy stays exact.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace viscera::tissue {

struct FungEnergyMap {
  double h, dh, d2h;  ///< h(e), dh/de, d2h/de2
};

inline FungEnergyMap fung_energy_map(double B, double e) {
  const double x = B * e;
  if (std::abs(x) < 1e-2) {  // series: the closed forms cancel here
    const double phi = 1 + x * (1.0 / 3 + x * (1.0 / 12 + x * (1.0 / 60 + x / 360)));
    const double dphi = 1.0 / 3 + x * (1.0 / 6 + x * (1.0 / 20 + x / 90));
    const double d2phi = 1.0 / 6 + x * (1.0 / 10 + x / 30);
    const double s = std::sqrt(phi), ds = dphi / (2 * s), d2s = d2phi / (2 * s) - dphi * dphi / (4 * s * s * s);
    return {e * s, s + x * ds, B * (2 * ds + x * d2s)};
  }
  const double em1 = std::expm1(x);
  const double s = std::sqrt(2 * (em1 - x) / (x * x));
  const double h = e * s;
  const double dh = em1 / (x * s);
  return {h, dh, (em1 + 1 - dh * dh) * B / (x * s)};  // h'' = (e^x - h'^2) / h, h = x s / B
}

/// Stiffening laws g(e) with the same small-strain start (g'(0) = 1, stiffness growing with |e|):
///  - exponential: Fung's (exp(B e) - 1) / B (stiffer in tension than in compression);
///  - odd_exponential: sign(e) (exp(B |e|) - 1) / B, odd in e (a shear response must be: an
///    isotropic solid's shear stress is odd in the shear strain). Energy map: h(e) = sign(e)
///    h_exp(|e|), h' even, h'' odd: it jumps from -B/3 to B/3 at 0. In a bar it multiplies a
///    zero tension there; in a tetrahedron it multiplies (H h)_k, which the other edges' strains
///    make nonzero, so the tangent jumps where an edge crosses zero strain and Newton converges
///    only linearly near such a state (viscera-lab's specimen in compression: its residual
///    tolerance is tied to the data's noise, specimen_simulation.hpp);
///  - odd_polynomial: e (1 + B^2 e^2 / 6). Energy map h = e sqrt(q), q = 1 + c e^2, c = B^2 / 12:
///    h h' = e (1 + 2 c e^2) = g.
enum class StiffeningShape { exponential, odd_exponential, odd_polynomial };

inline FungEnergyMap stiffening_energy_map(StiffeningShape shape, double B, double e) {
  switch (shape) {
    case StiffeningShape::exponential: break;
    case StiffeningShape::odd_exponential: {
      const FungEnergyMap f = fung_energy_map(B, std::abs(e));
      const double sign = e < 0 ? -1.0 : 1.0;
      return {sign * f.h, f.dh, sign * f.d2h};
    }
    case StiffeningShape::odd_polynomial: {
      const double c = B * B / 12, q = 1 + c * e * e, sq = std::sqrt(q);
      return {e * sq, (1 + 2 * c * e * e) / sq, c * e * (3 + 2 * c * e * e) / (q * sq)};
    }
  }
  return fung_energy_map(B, e);
}

constexpr double kAsymmetryWidth = 0.005;

/// The energy map of a stiffening shape with B and the compression ratio r (r = 1: symmetric).
inline FungEnergyMap edge_energy_map(double B, double r, double e, StiffeningShape shape = StiffeningShape::exponential) {
  const FungEnergyMap f = stiffening_energy_map(shape, B, e);
  if (r == 1.0) return f;
  const double q = std::sqrt(r) - 1.0, w = kAsymmetryWidth;
  const double S = 1.0 / (1.0 + std::exp(e / w));  // logistic of -e/w: 1 in compression, 0 in tension
  const double dS = -S * (1 - S) / w, d2S = S * (1 - S) * (1 - 2 * S) / (w * w);
  const double c = 1 + q * S, dc = q * dS, d2c = q * d2S;
  return {c * f.h, dc * f.h + c * f.dh, d2c * f.h + 2 * dc * f.dh + c * f.d2h};
}

namespace lanes {

/// exp(x) without branches or library calls, so that a loop over lanes vectorises: x = n ln 2 + r
/// (Cody and Waite's two-part ln 2, n by the 1.5 * 2^52 rounding trick), exp(r) for |r| <= ln 2 / 2
/// by its Taylor polynomial to degree 13 (truncation below 2e-17 relative), times 2^n built in
/// the exponent's bits. x is clamped to [-708, 709]: exp stays finite and normal. Within 2 ulp of
/// std::exp over that range (tests/tissue/fung_map_test.cpp).
inline double exp(double x) {
  x = std::min(std::max(x, -708.0), 709.0);
  constexpr double kShift = 0x1.8p52, kLog2e = 1.4426950408889634, kLn2Hi = 0x1.62e42fee00000p-1, kLn2Lo = 0x1.a39ef35793c76p-33;
  const double t = x * kLog2e + kShift;  // n in the low bits of t's mantissa
  const double n = t - kShift;
  const double r = (x - n * kLn2Hi) - n * kLn2Lo;
  double p = 1.0 / 6227020800.0;  // 1 / 13!
  for (const double c : {1.0 / 479001600.0, 1.0 / 39916800.0, 1.0 / 3628800.0, 1.0 / 362880.0, 1.0 / 40320.0, 1.0 / 5040.0, 1.0 / 720.0, 1.0 / 120.0,
                         1.0 / 24.0, 1.0 / 6.0, 0.5, 1.0, 1.0})
    p = p * r + c;
  const std::int64_t k = std::bit_cast<std::int64_t>(t) - std::bit_cast<std::int64_t>(kShift);
  return p * std::bit_cast<double>((k + 1023) << 52);
}

/// h(e) and h'(e) of edge_energy_map for one edge, branch-free (both of Fung's forms, the series
/// and the closed one, computed and one selected; the shapes by arithmetic), for the force loop's
/// lanes. The same function as edge_energy_map to a few ulp; h'' is not needed there.
inline void edge_energy_map(double B, double r, StiffeningShape shape, double e, double& h, double& dh) {
  const bool odd = shape == StiffeningShape::odd_exponential;
  // Fung's exponential of x = B e (odd: B |e|): phi(x) = 2 (e^x - 1 - x) / x^2, h = e sqrt(phi).
  const double x = B * (odd ? std::fabs(e) : e);
  // |x| < 0.5: phi and phi' by their series, 2 x^k / (k + 2)! (terms to x^12: below 1e-17).
  double phi = 2.0 / 87178291200.0, dphi = 0.0;  // 2 / 14!
  for (const double c : {2.0 / 6227020800.0, 2.0 / 479001600.0, 2.0 / 39916800.0, 2.0 / 3628800.0, 2.0 / 362880.0, 2.0 / 40320.0, 2.0 / 5040.0,
                         2.0 / 720.0, 2.0 / 120.0, 2.0 / 24.0, 2.0 / 6.0, 1.0}) {
    dphi = dphi * x + phi;
    phi = phi * x + c;
  }
  const double s_series = std::sqrt(phi), dh_series = s_series + x * dphi / (2 * s_series);
  // Otherwise the closed form (x never 0 where it is taken; a lane that does not take it may
  // compute 0/0 harmlessly).
  const double em1 = exp(x) - 1.0;
  const double s_closed = std::sqrt(2 * (em1 - x) / (x * x)), dh_closed = em1 / (x * s_closed);
  const bool series = std::fabs(x) < 0.5;
  const double s = series ? s_series : s_closed;
  double hv = e * s, dhv = series ? dh_series : dh_closed;
  if (shape == StiffeningShape::odd_polynomial) {
    const double c = B * B / 12, q = 1 + c * e * e, sq = std::sqrt(q);
    hv = e * sq;
    dhv = (1 + 2 * c * e * e) / sq;
  }
  // Asymmetry: h scaled by c(e) = 1 + (sqrt(r) - 1) S(e), S the logistic of -e / w.
  if (r != 1.0) {
    const double q = std::sqrt(r) - 1.0, S = 1.0 / (1.0 + exp(e / kAsymmetryWidth)), dS = -S * (1 - S) / kAsymmetryWidth;
    const double c = 1 + q * S;
    dhv = q * dS * hv + c * dhv;
    hv = c * hv;
  }
  h = hv;
  dh = dhv;
}

}  // namespace lanes

}  // namespace viscera::tissue
