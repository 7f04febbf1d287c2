// Derived material constants against closed forms.
#include <numbers>

#include "check.hpp"
#include "granulate/material.hpp"

using namespace granulate;

namespace {
MaterialParams params(ForceModel model, InfluenceKind influence, double K, double G) {
  MaterialParams p;
  p.model = model;
  p.density = 1000;
  p.bulk_modulus = K;
  p.shear_modulus = G;
  p.horizon = 3e-3;
  p.fracture_energy = 50;
  p.influence = influence;
  return p;
}
}  // namespace

TEST_CASE("pmb 3D constants: c = 18K/(pi delta^4), s0 = sqrt(5 Gc / (9 K delta))") {
  const auto m =
      Material::make(params(ForceModel::pmb, InfluenceKind::constant, 2e9, 1.2e9), 3, PlaneMode::strain);
  const double delta = 3e-3;
  CHECK_CLOSE(m.micromodulus, 18 * 2e9 / (std::numbers::pi * std::pow(delta, 4)), 1e-6);
  CHECK_CLOSE(m.critical_stretch, std::sqrt(5 * 50 / (9 * 2e9 * delta)), 1e-6);
}

TEST_CASE("pmb 2D constants: c = 12 kappa/(pi delta^3), s0 = sqrt(pi Gc / (3 kappa delta))") {
  const double K = 2e9, G = 1.2e9, delta = 3e-3;
  const auto m = Material::make(params(ForceModel::pmb, InfluenceKind::constant, K, G), 2, PlaneMode::strain);
  const double kappa = K + G / 3;
  CHECK_CLOSE(m.dilatation_modulus, kappa, 1e-12);
  CHECK_CLOSE(m.micromodulus, 12 * kappa / (std::numbers::pi * std::pow(delta, 3)), 1e-6);
  CHECK_CLOSE(m.critical_stretch, std::sqrt(std::numbers::pi * 50 / (3 * kappa * delta)), 1e-6);
}

TEST_CASE("planar dilatation moduli") {
  const double K = 3e9, G = 1e9;
  const auto strain =
      Material::make(params(ForceModel::lps, InfluenceKind::linear, K, G), 2, PlaneMode::strain);
  const auto stress =
      Material::make(params(ForceModel::lps, InfluenceKind::linear, K, G), 2, PlaneMode::stress);
  const double E = 9 * K * G / (3 * K + G), nu = (3 * K - 2 * G) / (2 * (3 * K + G));
  const double lambda = K - 2 * G / 3;
  CHECK_CLOSE(strain.dilatation_modulus, lambda + G, 1e-12);
  CHECK_CLOSE(stress.dilatation_modulus, E / (2 * (1 - nu)), 1e-12);
  CHECK_CLOSE(strain.deviatoric_factor, 8, 0);
}

TEST_CASE("lps with omega = delta/r and nu = 1/4 has pmb's critical stretch (dilatation term vanishes)") {
  for (int d : {2, 3}) {
    const double G = 1e9, K = 5 * G / 3;
    const auto lps =
        Material::make(params(ForceModel::lps, InfluenceKind::inverse, K, G), d, PlaneMode::strain);
    const auto pmb =
        Material::make(params(ForceModel::pmb, InfluenceKind::constant, K, G), d, PlaneMode::strain);
    CHECK_CLOSE(lps.critical_stretch, pmb.critical_stretch, 2e-3);
  }
}

TEST_CASE("lps pair fracture coefficient: 3G for omega = delta/r in 3D (Madenci & Oterkus)") {
  CHECK_CLOSE(fracture_coefficients(ForceModel::lps, InfluenceKind::inverse, 3).pair, 3.0, 2e-3);
  CHECK_CLOSE(fracture_coefficients(ForceModel::lps, InfluenceKind::constant, 3).pair, 3.125, 1e-6);
  CHECK_CLOSE(fracture_coefficients(ForceModel::lps, InfluenceKind::constant, 2).pair,
              32 / (5 * std::numbers::pi), 1e-6);
  // The dilatation coefficient is positive and smaller than the pair one.
  for (int d : {2, 3}) {
    const auto c = fracture_coefficients(ForceModel::lps, InfluenceKind::linear, d);
    CHECK(c.dilatation > 0);
    CHECK(c.dilatation < c.pair);
  }
}

TEST_CASE("bad materials are refused") {
  auto p = params(ForceModel::lps, InfluenceKind::linear, 1e9, 1e9);
  p.density = -1;
  CHECK_THROWS(Material::make(p, 3, PlaneMode::strain), InputError);
  p = params(ForceModel::lps, InfluenceKind::linear, -1e9, 1e9);
  CHECK_THROWS(Material::make(p, 3, PlaneMode::strain), InputError);
  p = params(ForceModel::lps, InfluenceKind::linear, 1e9, 1e9);
  p.fracture_energy = 0;
  CHECK_THROWS(Material::make(p, 3, PlaneMode::strain), InputError);
  p.fracture = false;
  CHECK(!std::isfinite(Material::make(p, 3, PlaneMode::strain).critical_stretch));
  p.horizon = 0;
  CHECK_THROWS(Material::make(p, 3, PlaneMode::strain), InputError);
}
