// Exact sums (exact_accumulator.hpp) and the order-free body measures built on them
// (contact/body_sums.hpp).
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "check.hpp"
#include "fixtures.hpp"
#include "granulate/contact/block_sums.hpp"
#include "granulate/contact/body_sums.hpp"
#include "granulate/exact_accumulator.hpp"
#include "granulate/run_sums.hpp"
#include "granulate/simulation.hpp"

using namespace granulate;

namespace {

__extension__ typedef __int128 int128;  // the reference sums' integers

real exact_sum(const std::vector<real>& terms) {
  ExactAccumulator sum;
  for (const real x : terms) sum.add(x);
  return sum.rounded();
}

bool same_bits(real a, real b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace

TEST_CASE("exact sums: cancellation, ties to even, subnormals, overflow, non-finite terms") {
  const real big = std::numeric_limits<real>::max(), tiny = std::numeric_limits<real>::denorm_min();
  const real inf = std::numeric_limits<real>::infinity();
  CHECK(exact_sum({1e300, 1.0, -1e300}) == 1.0);
  CHECK(exact_sum({1.0, 1e-300, -1.0}) == 1e-300);
  CHECK(exact_sum({0.1, 0.2, -0.3}) == 0x1p-55);                                          // math.fsum's
  CHECK(exact_sum({1.0, std::ldexp(1.0, -53)}) == 1.0);                                   // tie: to even
  CHECK(exact_sum({1.0, std::ldexp(1.0, -53), std::ldexp(1.0, -120)}) == 1.0 + 0x1p-52);  // past it: up
  CHECK(exact_sum({1.0 + 0x1p-52, std::ldexp(1.0, -53)}) == 1.0 + 0x1p-51);               // tie: odd, up
  CHECK(exact_sum({-1.0 - 0x1p-52, -std::ldexp(1.0, -53)}) == -1.0 - 0x1p-51);            // the same below 0
  CHECK(exact_sum({-1.0, -std::ldexp(1.0, -53), std::ldexp(1.0, -120)}) == -1.0);         // short of the tie
  CHECK(exact_sum({tiny, tiny, tiny}) == 3 * tiny);
  CHECK(exact_sum({0x1p-1022, -tiny}) == 0x1p-1022 - tiny);
  CHECK(exact_sum({big, big, -big}) == big);
  CHECK(exact_sum({big, big}) == inf);
  CHECK(exact_sum({-big, -big}) == -inf);
  CHECK(exact_sum({inf, 1.0, -3.0}) == inf);
  CHECK(std::isnan(exact_sum({inf, -inf, 1.0})));
  CHECK(same_bits(exact_sum({-0.0}), 0.0));
  CHECK(same_bits(exact_sum({1.5, -1.5}), 0.0));
  CHECK(same_bits(exact_sum({}), 0.0));
  CHECK(exact_sum({3.25}) == 3.25);
}

TEST_CASE("exact sums of random terms equal an integer reference, and split anyhow they add up") {
  // Terms of 40-bit mantissas times 2^-60 .. 2^20: exact in a 128-bit integer of 2^-100, whose
  // conversion to double rounds to nearest, ties to even.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> mantissa(-(std::int64_t{1} << 40), std::int64_t{1} << 40);
  std::uniform_int_distribution<int> exponent(-60, 20);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<real> terms;
    int128 reference = 0;
    const int count = 1 + trial * 7;
    for (int k = 0; k < count; ++k) {
      const std::int64_t m = mantissa(rng);
      const int e = exponent(rng);
      terms.push_back(std::ldexp(static_cast<real>(m), e));
      reference += static_cast<int128>(m) << (e + 60);
    }
    const real expected = std::ldexp(static_cast<real>(reference), -60);
    ExactAccumulator whole, parts[3];
    for (std::size_t k = 0; k < terms.size(); ++k) {
      whole.add(terms[k]);
      parts[rng() % 3].add(terms[k]);
    }
    CHECK(same_bits(whole.rounded(), expected));
    // As processes would: digits summed digit by digit, or accumulators added.
    ExactAccumulator::Digits digits{};
    for (const auto& part : parts) {
      const auto d = part.digits();
      for (int k = 0; k < ExactAccumulator::digit_count; ++k) digits[k] += d[k];
    }
    CHECK(same_bits(ExactAccumulator::from_digits(digits, 0.0).rounded(), expected));
    ExactAccumulator joined = parts[2];
    joined.add(parts[0]);
    joined.add(parts[1]);
    CHECK(same_bits(joined.rounded(), expected));
  }
}

TEST_CASE("a large body's motion and rotation: the same bits from whole blocks dealt to parts") {
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  model->add_material(granulate_test::test_material());
  granulate_test::add_square(*model, 0, 70, 0.3, -0.2);  // 4,900 nodes: measured order-free
  Simulation sim(model);
  const index_t n = model->node_count();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-1, 1);
  auto& state = sim.state();
  for (index_t i = 0; i < n; ++i) {
    for (int k = 0; k < 2; ++k) {
      state.positions[3 * i + k] += 2e-4 * jitter(rng) + 0.1 * model->reference_positions()[3 * i + 1 - k];
      state.velocities[3 * i + k] =
          jitter(rng) + (k == 0 ? -30 : 30) * model->reference_positions()[3 * i + 1 - k];
    }
  }
  std::vector<index_t> nodes(n);
  for (index_t i = 0; i < n; ++i) nodes[i] = i;
  CHECK(measured_order_free(*model, nodes.data(), n));
  CHECK(!measured_order_free(*model, nodes.data() + 64, 64));  // one block: measured in one pass
  const BodyMotion whole = measure_body(*model, state, nodes.data(), n, 2);
  const contact::matrix3 moment = moment_order_free(*model, state, nodes.data(), n);

  // Whole blocks of 64 dealt at random to three parts, each pass's sums added as processes would.
  std::vector<index_t> part_nodes[3];
  const index_t block = kRunBlock;
  for (index_t first = 0; first < n; first += block) {
    auto& part = part_nodes[rng() % 3];
    for (index_t i = first; i < std::min(n, first + block); ++i) part.push_back(i);
  }
  auto size = [](const std::vector<index_t>& part) { return static_cast<index_t>(part.size()); };
  const vec3 origin = body_origin(*model, 0);
  CentreSums first;
  for (const auto& part : part_nodes) first.add(centre_sums(*model, state, part.data(), size(part), origin));
  const BodyCentres centres = centres_from(first, origin);
  MotionSums motion;
  MomentSums moments;
  for (const auto& part : part_nodes) {
    motion.add(motion_sums(*model, state, part.data(), size(part), centres.current));
    moments.add(moment_sums(*model, state, part.data(), size(part), centres));
  }
  const BodyMotion joined = motion_from(motion, centres.current, 2);
  for (int k = 0; k < 3; ++k) {
    CHECK(same_bits(joined.centre[k], whole.centre[k]));
    CHECK(same_bits(joined.velocity[k], whole.velocity[k]));
    CHECK(same_bits(joined.angular_velocity[k], whole.angular_velocity[k]));
  }
  CHECK(same_bits(joined.inverse_inertia[2], whole.inverse_inertia[2]));
  const contact::matrix3 joined_moment = moment_from(moments);
  for (int k = 0; k < 9; ++k) CHECK(same_bits(joined_moment[k], moment[k]));

  // Against sums in node order about the origin (long double): the spin about the centre.
  long double mass = 0, cx = 0, cy = 0, px = 0, py = 0;
  for (index_t i = 0; i < n; ++i) {
    const long double m = model->density(i) * model->volumes()[i];
    mass += m;
    cx += m * state.positions[3 * i];
    cy += m * state.positions[3 * i + 1];
    px += m * state.velocities[3 * i];
    py += m * state.velocities[3 * i + 1];
  }
  CHECK_CLOSE(whole.centre[0], static_cast<double>(cx / mass), 1e-14);
  CHECK_CLOSE(whole.centre[1], static_cast<double>(cy / mass), 1e-14);
  CHECK_CLOSE(whole.velocity[0], static_cast<double>(px / mass), 1e-13);
  CHECK_CLOSE(whole.velocity[1], static_cast<double>(py / mass), 1e-13);
  CHECK_CLOSE(whole.angular_velocity[2], 30.0, 2e-2);  // v = 30 (-y, x): a turn about z, sheared
}

TEST_CASE("a small fragment of a large body, far from where it was: its inertia, not round-off") {
  // Nodes 63 and 64 (two blocks, 1 mm apart) carried 1 m away: moments about the smallest node's
  // reference position would lose the fragment's inertia (1e-7 of theirs) to cancellation.
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  model->add_material(granulate_test::test_material());
  granulate_test::add_square(*model, 0, 70, 0.0, 0.0);
  Simulation sim(model);
  auto& state = sim.state();
  const index_t pair[2] = {63, 64};
  for (const index_t i : pair) {
    state.positions[3 * i] += 1.0;
    state.positions[3 * i + 1] += 1.0;
    state.velocities[3 * i] = 0;
    state.velocities[3 * i + 1] = i == 63 ? -1.0 : 1.0;  // turning at 2 m/s / 1 mm
  }
  CHECK(measured_order_free(*model, pair, 2));
  const BodyMotion motion = measure_body(*model, state, pair, 2, 2);
  const real m = model->density(63) * model->volumes()[63];
  CHECK_CLOSE(motion.inverse_inertia[2], 1 / (2 * m * 0.25e-6), 1e-12);
  CHECK_CLOSE(motion.angular_velocity[2], 2000.0, 1e-12);
  CHECK_CLOSE(motion.centre[0], 1.0 + 64e-3, 1e-15);
  const index_t one = 64;
  CHECK(!measured_order_free(*model, &one, 1));
  CHECK(measure_body(*model, state, &one, 1, 2).inverse_inertia[2] == 0);
}

TEST_CASE("block sums: whole blocks of nodes dealt to parts add up to the whole's bits") {
  // Terms of 3 items from 1,000 nodes (an item's nodes in node order, sweeps apart), the
  // blocks of 64 dealt to 3 parts at random.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> term(-1, 1);
  struct Entry {
    std::size_t item;
    index_t node;
    BlockSums<2>::Terms terms;
  };
  std::vector<Entry> sweeps[2];
  for (auto& sweep : sweeps)
    for (index_t i = 0; i < 1000; ++i)
      if (rng() % 3 == 0) sweep.push_back({rng() % 3, i, {term(rng) * 1e3, term(rng) * 1e-3}});
  // Part 2 holds one block: its sweeps meet there, so they must be summed apart.
  const std::size_t part_of_block[16] = {0, 1, 1, 1, 0, 0, 1, 2, 1, 0, 0, 1, 1, 0, 0, 1};
  auto sum = [&](int part) {  // part -1: every node
    BlockSums<2> sums;
    sums.start(3, [](std::size_t) { return true; });
    for (const auto& sweep : sweeps) {
      for (const Entry& e : sweep)
        if (part < 0 || part_of_block[e.node / kRunBlock] == static_cast<std::size_t>(part))
          sums.add(e.item, e.node, e.terms);
      sums.finish_sweep();
    }
    return sums;
  };
  const BlockSums<2> whole = sum(-1);
  const BlockSums<2> parts[3] = {sum(0), sum(1), sum(2)};
  for (std::size_t item = 0; item < 3; ++item) {
    ExactSums<2> joined = parts[2].exact(item);
    joined.add(parts[0].exact(item));
    joined.add(parts[1].exact(item));
    const auto expected = whole.rounded(item), found = joined.rounded();
    CHECK(same_bits(found[0], expected[0]) && same_bits(found[1], expected[1]));
  }
}
