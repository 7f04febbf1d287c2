// Evaluators against hand-computed values.
#include "check.hpp"
#include "granulate/influence.hpp"
#include "granulate/loading.hpp"
#include "granulate/peridynamics/critical_stretch.hpp"
#include "granulate/peridynamics/lps.hpp"
#include "granulate/peridynamics/pmb.hpp"

using namespace granulate;

TEST_CASE("lps pair force is w ((A_i theta_i + A_j theta_j) r + (B_i + B_j) e)") {
  // w = 2, r = 0.5, e = 0.01, pressures 3 and 5, deviatoric 7 and 11.
  CHECK_CLOSE(lps::pair_force(2.0, 0.5, 0.01, 3.0, 5.0, 7.0, 11.0), 2.0 * (8.0 * 0.5 + 18.0 * 0.01), 1e-15);
  CHECK_CLOSE(lps::dilatation_term(2.0, 0.5, 0.01), 0.01, 1e-15);
  // deviatoric extension e - theta r / d = 0.01 - 0.03 * 0.5 / 3 = 0.005
  CHECK_CLOSE(lps::deviatoric_energy_term(2.0, 0.5, 0.01, 0.03, 1.0 / 3.0), 2.0 * 0.005 * 0.005, 1e-12);
}

TEST_CASE("pmb force is c w s and its energy term integrates it") {
  CHECK_CLOSE(pmb::pair_force(10.0, 2.0, 0.01), 0.2, 1e-15);
  // d(energy per pair)/de: energy of the pair = 2 * energy_term (one per end) = c w s^2 r / 2,
  // derivative in e = c w s = force.
  const double c = 10, w = 2, r = 0.5, e = 0.003, step = 1e-7;
  const double energy_plus = 2 * pmb::energy_term(c, w, (e + step) / r, r);
  const double energy_minus = 2 * pmb::energy_term(c, w, (e - step) / r, r);
  CHECK_CLOSE((energy_plus - energy_minus) / (2 * step), pmb::pair_force(c, w, e / r), 1e-7);
}

TEST_CASE("influence functions at special points") {
  CHECK_CLOSE(influence(InfluenceKind::constant, 0.7), 1.0, 0);
  CHECK_CLOSE(influence(InfluenceKind::linear, 0.25), 0.75, 1e-15);
  CHECK_CLOSE(influence(InfluenceKind::gaussian, 0.4), std::exp(-1.0), 1e-15);
  CHECK_CLOSE(influence(InfluenceKind::inverse, 0.5), 2.0, 1e-15);
}

TEST_CASE("critical stretch breaks in tension only unless asked") {
  const CriticalStretch tension{0.01, false}, both{0.01, true};
  CHECK(!tension.breaks(0.01));
  CHECK(tension.breaks(0.0101));
  CHECK(!tension.breaks(-0.5));
  CHECK(both.breaks(-0.0101));
  CHECK(!both.breaks(-0.0099));
}

TEST_CASE("time functions: values and rates by finite differences") {
  using K = TimeFunction::Kind;
  const TimeFunction functions[] = {{K::constant, 2, 0},      {K::linear, 2, 0},
                                    {K::quadratic, 2, 3},     {K::sine, 2, 5},
                                    {K::smooth_ramp, 2, 0.4}, {K::velocity_ramp, 2, 0.4}};
  for (const TimeFunction& f : functions) {
    for (double t : {0.05, 0.2, 0.33, 0.7}) {
      const double h = 1e-6;
      CHECK(granulate_test::close((f.value(t + h) - f.value(t - h)) / (2 * h), f.rate(t), 1e-6, 1e-8));
    }
  }
  CHECK_CLOSE(TimeFunction({K::smooth_ramp, 2, 0.4}).value(1.0), 2.0, 1e-15);
  CHECK_CLOSE(TimeFunction({K::velocity_ramp, 2, 0.4}).rate(1.0), 2.0, 1e-15);
  CHECK_CLOSE(TimeFunction({K::velocity_ramp, 2, 0.4}).value(1.0), 2.0 * (0.2 + 0.6), 1e-12);
  CHECK_THROWS(TimeFunction({K::smooth_ramp, 2, 0}).validate(), InputError);
}
