#pragma once
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
#include <cmath>

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

}  // namespace viscera::tissue
