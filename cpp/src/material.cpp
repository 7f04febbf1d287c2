#include "granulate/material.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <sstream>
#include <tuple>

namespace granulate {
namespace {

constexpr int quadrature_points = 160;

std::string format(real value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void require_positive(real value, const char* name, const char* fix) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw InputError(std::string("material ") + name + " must be a positive finite number, got " +
                     format(value) + "; " + fix);
  }
}

/// Dilatation of a node at depth zeta (in horizons) below the separation plane when the two
/// half-spaces are pulled apart by u = s0 * delta * v, divided by s0 * v (see fracture_coefficients).
/// moment: int_0^1 J xi^4 dxi in 3D, int_0^1 J xi^3 dxi in 2D.
real separation_dilatation_slope(InfluenceKind influence_kind, int dimension, real moment, real zeta,
                                 real v) {
  const int n = quadrature_points;
  const real step = (1.0 - zeta) / n;
  real sum = 0;
  for (int k = 0; k < n; ++k) {
    const real rho = zeta + (k + 0.5) * step;
    const real cos_low = zeta / rho;                // the bond reaches the other side
    const real cos_high = v > rho ? rho / v : 1.0;  // the bond is still intact
    if (cos_high <= cos_low) continue;
    const real weight = influence(influence_kind, rho);
    if (dimension == 3) {
      sum += weight * rho * rho * rho * (cos_high * cos_high - cos_low * cos_low);
    } else {
      sum += weight * rho * rho * (std::sqrt(1.0 - cos_low * cos_low) - std::sqrt(1.0 - cos_high * cos_high));
    }
  }
  sum *= step;
  if (dimension == 3) return 3.0 / (4.0 * moment) * sum;
  return 2.0 / (std::numbers::pi * moment) * sum;
}

}  // namespace

real influence_moment(InfluenceKind influence_kind, int power) {
  const int n = 4000;
  real sum = 0;
  for (int k = 0; k < n; ++k) {
    const real xi = (k + 0.5) / n;
    sum += influence(influence_kind, xi) * std::pow(xi, power);
  }
  return sum / n;
}

namespace {

FractureCoefficients compute_fracture_coefficients(ForceModel model, InfluenceKind influence_kind,
                                                   int dimension) {
  FractureCoefficients result;
  if (model == ForceModel::pmb) {
    // Pair energy w = c J s^2 r / 2 integrated over the bonds crossing a unit area:
    // 3D: pi int w r^3 dr, 2D: 2 int w r^2 dr.
    result.pair = dimension == 3 ? std::numbers::pi / 2.0 * influence_moment(influence_kind, 4)
                                 : influence_moment(influence_kind, 3);
    return result;
  }
  // LPS energy W = (kappa_d - a G/d^2) theta^2 / 2 + (a G / 2m) sum J e^2 V: the second term is
  // a pair energy (a G / m) J e^2 per pair, released bond by bond whatever the path.
  if (dimension == 3) {
    result.pair = 15.0 / 4.0 * influence_moment(influence_kind, 5) / influence_moment(influence_kind, 4);
  } else {
    result.pair =
        8.0 / std::numbers::pi * influence_moment(influence_kind, 4) / influence_moment(influence_kind, 3);
  }
  // The dilatation term depends on the path. Along rigid separation (opening u, a bond at angle
  // phi to the normal has e = u cos(phi) and breaks at u = s0 r / cos(phi)) the work per unit area
  // is 2 int_0^delta dz int_0^inf (kappa_d - a G/d^2) u g(z,u)^2 du with theta = u g. In units of
  // s0^2 delta this is 2 int_0^1 dzeta int_0^inf v G(zeta, v)^2 dv.
  const int n = quadrature_points;
  const real moment = influence_moment(influence_kind, dimension == 3 ? 4 : 3);
  real total = 0;
  for (int iz = 0; iz < n; ++iz) {
    const real zeta = (iz + 0.5) / n;
    real inner = 0;
    for (int iv = 0; iv < n; ++iv) {
      const real v = (iv + 0.5) / n;  // v in (0, 1)
      const real g = separation_dilatation_slope(influence_kind, dimension, moment, zeta, v);
      inner += v * g * g / n;
      const real t = (iv + 0.5) / n;  // v = 1/t in (1, inf): v dv = dt / t^3
      const real g_far = separation_dilatation_slope(influence_kind, dimension, moment, zeta, 1.0 / t);
      inner += g_far * g_far / (t * t * t) / n;
    }
    total += inner / n;
  }
  result.dilatation = 2.0 * total;
  return result;
}

}  // namespace

FractureCoefficients fracture_coefficients(ForceModel model, InfluenceKind influence_kind, int dimension) {
  // They depend on these three alone, and LPS's double quadrature takes ~45 ms: each is computed
  // once per process, not at every Model (a distributed run builds its parts anew at migrations).
  static std::mutex mutex;
  static std::map<std::tuple<ForceModel, InfluenceKind, int>, FractureCoefficients> known;
  const std::lock_guard lock(mutex);
  const auto [place, added] = known.try_emplace({model, influence_kind, dimension});
  if (added) place->second = compute_fracture_coefficients(model, influence_kind, dimension);
  return place->second;
}

namespace {

/// The continuum PMB micromodulus c at horizon delta (Material::micromodulus).
real pmb_micromodulus(const Material& m, real delta) {
  const InfluenceKind influence = m.params.influence;
  if (m.dimension == 3) {
    return 18.0 * m.params.bulk_modulus /
           (4.0 * std::numbers::pi * std::pow(delta, 4) * influence_moment(influence, 3));
  }
  return 8.0 * m.dilatation_modulus /
         (2.0 * std::numbers::pi * std::pow(delta, 3) * influence_moment(influence, 2));
}

}  // namespace

real Material::critical_stretch_at(real delta) const {
  if (!params.fracture) return std::numeric_limits<real>::infinity();
  const real K = params.bulk_modulus;
  const real G = params.shear_modulus;
  real energy_per_stretch2;  // Gc / s0^2
  if (dimension == 2 && plane == PlaneMode::peridem) {
    energy_per_stretch2 = (3.0 * G + std::pow(0.75, 4) * (K - 5.0 * G / 3.0)) * delta;
  } else if (params.model == ForceModel::lps) {
    const real d = dimension;
    energy_per_stretch2 =
        delta *
        (fracture.pair * G + fracture.dilatation * (dilatation_modulus - deviatoric_factor * G / (d * d)));
  } else {
    energy_per_stretch2 = fracture.pair * pmb_micromodulus(*this, delta) * std::pow(delta, dimension + 2);
  }
  return energy_per_stretch2 > 0 ? std::sqrt(params.fracture_energy / energy_per_stretch2) : 0.0;
}

Material Material::make(const MaterialParams& params, int dimension, PlaneMode plane) {
  if (dimension != 2 && dimension != 3) {
    throw InputError("dimension must be 2 or 3, got " + std::to_string(dimension));
  }
  require_positive(params.density, "density", "give the mass density in kg/m^3");
  require_positive(params.bulk_modulus, "bulk_modulus", "give K in Pa (or E and nu)");
  require_positive(params.horizon, "horizon", "give the horizon in m (typically 3 mesh sizes)");
  require_positive(params.shear_modulus, "shear_modulus", "give G in Pa (or E and nu)");
  {
    const real nu = (3 * params.bulk_modulus - 2 * params.shear_modulus) /
                    (2 * (3 * params.bulk_modulus + params.shear_modulus));
    if (!(nu > -1.0 && nu < 0.5)) {
      throw InputError("material Poisson ratio " + format(nu) + " from K = " + format(params.bulk_modulus) +
                       " and G = " + format(params.shear_modulus) +
                       " is outside (-1, 0.5); check the elastic constants");
    }
  }
  if (params.fracture) {
    require_positive(params.fracture_energy, "fracture_energy (Gc)",
                     "give the critical energy release rate in J/m^2, or turn fracture off");
  }

  Material m;
  m.params = params;
  m.dimension = dimension;
  m.plane = plane;
  const real K = params.bulk_modulus;
  const real G = params.shear_modulus;
  const bool peridem = dimension == 2 && plane == PlaneMode::peridem;
  if (peridem && params.model != ForceModel::lps) {
    throw InputError("PeriDEM's 2D constants (plane 'peridem') are reproduced for the LPS model only");
  }
  if (dimension == 3 || peridem) {
    m.dilatation_modulus = K;
    m.deviatoric_factor = 15.0;
  } else {
    m.dilatation_modulus = plane == PlaneMode::strain ? K + G / 3.0 : 9.0 * K * G / (3.0 * K + 4.0 * G);
    m.deviatoric_factor = 8.0;
  }
  if (params.model == ForceModel::pmb) m.micromodulus = pmb_micromodulus(m, params.horizon);
  if (params.fracture && !peridem) {
    m.fracture = fracture_coefficients(params.model, params.influence, dimension);
  }
  m.critical_stretch = m.critical_stretch_at(params.horizon);
  if (!(m.critical_stretch > 0)) {
    throw InputError(
        "material constants give a non-positive fracture energy per stretch; "
        "check K and G (Poisson ratio near -1?)");
  }
  return m;
}

}  // namespace granulate
