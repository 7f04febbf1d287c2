// Peridynamic materials: user parameters and the constants derived from them.
#pragma once

#include "granulate/influence.hpp"
#include "granulate/types.hpp"

namespace granulate {

/// Force model of the bonds inside a particle.
///   lps: linear peridynamic solid (state-based; Silling et al. 2007, Le et al. 2014 in 2D)
///   pmb: prototype microelastic brittle (bond-based; Silling & Askari 2005)
enum class ForceModel : std::uint8_t { lps, pmb };

/// What the user gives (SI units).
struct MaterialParams {
  ForceModel model = ForceModel::lps;
  real density = 0;          ///< rho [kg/m^3]
  real bulk_modulus = 0;     ///< K, 3D bulk modulus [Pa]
  real shear_modulus = 0;    ///< G [Pa]
  real horizon = 0;          ///< delta [m], absolute; particles may carry their own (Model::add_particle)
  real fracture_energy = 0;  ///< critical energy release rate Gc [J/m^2]
  InfluenceKind influence = InfluenceKind::linear;
  bool fracture = true;               ///< false: elastic, bonds never break
  bool break_in_compression = false;  ///< true: |s| > s0 breaks, not only s > s0
};

/// Dimensionless energy-release coefficients of a model, such that rigidly separating two
/// half-spaces (every bond crossing the plane stretched until it breaks at s0) dissipates
///   Gc = s0^2 * delta * (pair * G + dilatation * (kappa_d - a_d G / d^2))          (LPS)
///   Gc = s0^2 * c * delta^(d+2) * pair                                            (PMB)
/// Computed by quadrature of the continuum bond integrals for the given influence function.
struct FractureCoefficients {
  real pair = 0;
  real dilatation = 0;
};
/// Constants a force loop needs, derived once from MaterialParams for one dimension and plane.
struct Material {
  MaterialParams params;
  int dimension = 3;
  PlaneMode plane = PlaneMode::strain;
  /// kappa_d: K in 3D; K + G/3 in plane strain; 9KG/(3K+4G) in plane stress [Pa].
  real dilatation_modulus = 0;
  /// a_d: 15 in 3D, 8 in 2D (deviatoric coefficient of the LPS force state).
  real deviatoric_factor = 0;
  /// Continuum PMB micromodulus c: 3D 18K / I1, 2D 8 kappa_d / I1, I1 = int J(r/delta) r dV
  /// [Pa/m^(d+1)]; used to derive s0. The force loop uses the per-node discrete form (pmb.hpp).
  real micromodulus = 0;
  /// s0, critical bond stretch at params.horizon (critical_stretch_at); infinity when fracture
  /// is off.
  real critical_stretch = 0;
  /// The fracture coefficients s0 is derived with (zero without fracture, and for PeriDEM's
  /// 2D constants, which have their own).
  FractureCoefficients fracture;

  /// s0 at horizon delta [m]: sqrt(Gc / (energy per squared stretch at delta)), from the
  /// material's constants alone, so that a particle's s0 does not depend on which particle's
  /// horizon made the material (a distributed run's parts make it of other particles than the
  /// whole run); 0 when the constants give no positive energy (make refuses them).
  real critical_stretch_at(real delta) const;

  /// Validates the parameters (throws InputError naming the bad one) and derives the constants.
  static Material make(const MaterialParams& params, int dimension, PlaneMode plane);
};

/// The fracture coefficients of a force model and influence function in `dimension`: a quadrature
/// of ~10^7 points for LPS, made once per process for each of them (thread-safe) and kept.
FractureCoefficients fracture_coefficients(ForceModel model, InfluenceKind influence, int dimension);

/// Continuum moment int_0^1 J(xi) xi^p dxi of an influence function (midpoint quadrature).
real influence_moment(InfluenceKind influence, int power);

}  // namespace granulate
