// Bond families, forces against -dE/dx by finite differences, Newton's third law, input errors.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>

#include "check.hpp"
#include "fixtures.hpp"
#include "granulate/simulation.hpp"

using namespace granulate;

namespace {

/// A block of n^d lattice nodes of spacing h with a material of horizon 3h.
std::shared_ptr<Model> lattice_block(int dimension, int n, ForceModel force_model, InfluenceKind influence,
                                     bool fracture = false, double offset = 0.0, double volume_spread = 0.0) {
  const double h = 1e-3;
  auto model = std::make_shared<Model>(dimension, PlaneMode::strain);
  MaterialParams p;
  p.model = force_model;
  p.density = 1200;
  p.bulk_modulus = 2e9;
  p.shear_modulus = 1e9;
  p.horizon = 3 * h;
  p.fracture_energy = 50;
  p.fracture = fracture;
  p.influence = influence;
  const index_t material = model->add_material(p);
  std::vector<double> x, v;
  const int nz = dimension == 3 ? n : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        x.insert(x.end(),
                 {offset + (i + 0.5) * h, offset + (j + 0.5) * h, dimension == 3 ? (k + 0.5) * h : 0.0});
        // volume_spread > 0: unequal volumes, a smooth pattern so no volume is near zero
        const double factor = 1.0 + volume_spread * std::sin(1.7 * i + 2.3 * j + 0.9 * k);
        v.push_back(factor * (dimension == 3 ? h * h * h : h * h));
      }
  model->add_particle(x, v, material, h);
  return model;
}

}  // namespace

TEST_CASE("bond families: interior counts, symmetry, partial volumes") {
  auto model2 = lattice_block(2, 11, ForceModel::lps, InfluenceKind::constant);
  model2->finalize();
  const index_t centre = 5 * 11 + 5;
  CHECK(model2->node_bonds(centre).count == 28);  // lattice points with |(i,j)| <= 3
  auto model3 = lattice_block(3, 9, ForceModel::lps, InfluenceKind::constant);
  model3->finalize();
  CHECK(model3->node_bonds((4 * 9 + 4) * 9 + 4).count == 122);
  // every node at least one horizon inside has the full family, wherever the lattice sits
  for (double offset : {0.0, -0.0123, 0.37}) {
    auto shifted = lattice_block(2, 24, ForceModel::lps, InfluenceKind::constant, false, offset);
    shifted->finalize();
    for (int j = 3; j < 21; ++j)
      for (int i = 3; i < 21; ++i) CHECK(shifted->node_bonds(j * 24 + i).count == 28);
  }
  // every bond i->j has j->i with the same length
  for (index_t i = 0; i < model2->node_count(); ++i) {
    const NodeBonds bi = model2->node_bonds(i);
    for (index_t k = 0; k < bi.count; ++k) {
      const NodeBonds bj = model2->node_bonds(bi.neighbor(k));
      bool found = false;
      for (index_t q = 0; q < bj.count; ++q) {
        if (bj.neighbor(q) == i) found = (bj.length(q) == bi.length(k));
      }
      CHECK(found);
    }
  }
  // a bond of length exactly delta keeps half its volume; one of length 2h all of it (weights
  // are stored in single precision: 6e-8 relative)
  const NodeBonds bc = model2->node_bonds(centre);
  for (index_t k = 0; k < bc.count; ++k) {
    const double r = bc.length(k) / 1e-3;
    if (std::abs(r - 3.0) < 1e-9) CHECK_CLOSE(bc.weight(k), 0.5e-6, 1e-7);
    if (std::abs(r - 2.0) < 1e-9) CHECK_CLOSE(bc.weight(k), 1e-6, 1e-7);
  }
}

TEST_CASE("a shape placed many times shares one bond family; lengths and weights scale") {
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  MaterialParams p;
  p.density = 1000;
  p.bulk_modulus = 1e9;
  p.shear_modulus = 6e8;
  p.horizon = 3e-3;  // absolute: scale 2 needs a family of its own (horizon 1.5 h in shape units)
  p.fracture = false;
  const index_t absolute = model->add_material(p);
  std::vector<double> x, v;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      x.insert(x.end(), {(i + 0.5) * 1e-3, (j + 0.5) * 1e-3, 0.0});
      v.push_back(1e-6);
    }
  const index_t shape = model->add_shape(x, v, 1e-3);
  auto placed = [&](double scale, double angle, double shift) {
    std::vector<double> out(x.size());
    for (std::size_t a = 0; a < x.size(); a += 3) {
      out[a] = scale * (std::cos(angle) * x[a] - std::sin(angle) * x[a + 1]) + shift;
      out[a + 1] = scale * (std::sin(angle) * x[a] + std::cos(angle) * x[a + 1]);
    }
    return out;
  };
  model->add_particle(shape, absolute, placed(1.0, 0.0, 0.0), 1.0);
  model->add_particle(shape, absolute, placed(1.0, 0.7, 0.05), 1.0);
  model->add_particle(shape, absolute, placed(1.5, 1.1, 0.10), 1.5);
  CHECK_THROWS(model->add_particle(shape, absolute, placed(1.5, 0.0, 0.2), 1.0), InputError);  // not rigid
  model->finalize();
  CHECK(model->families().size() == 2);
  const NodeBonds a = model->node_bonds(27), b = model->node_bonds(64 + 27), c = model->node_bonds(128 + 27);
  CHECK(a.count == b.count && a.neighbors == b.neighbors);  // shared storage
  CHECK(a.count == 28 && c.count == 12);  // horizons 3 h and (3 mm / 1.5) = 2 h in shape units
  CHECK_CLOSE(model->volumes()[128 + 27], 2.25e-6, 1e-12);
  for (index_t k = 0; k < c.count; ++k) {
    const index_t j = c.neighbor(k);
    const auto& X = model->reference_positions();
    const double r = std::hypot(X[3 * j] - X[3 * (128 + 27)], X[3 * j + 1] - X[3 * (128 + 27) + 1]);
    CHECK_CLOSE(c.length(k), r, 1e-9);
  }
}

TEST_CASE("forces equal -dE/dx (finite differences), Newton's third law holds") {
  // Unequal volumes: each bond is evaluated once and gives w_ij = J beta V_j to i and
  // w_ji = J beta V_i to j, which only -dE/dx with V_i != V_j tells apart.
  for (int d : {2, 3}) {
    for (ForceModel force_model : {ForceModel::lps, ForceModel::pmb}) {
      auto model = lattice_block(d, d == 2 ? 8 : 5, force_model, InfluenceKind::linear, false, 0.0, 0.3);
      Simulation sim(model);
      std::mt19937 rng(42);
      std::uniform_real_distribution<double> jitter(-2e-5, 2e-5);
      auto& x = sim.state().positions;
      for (std::size_t k = 0; k < x.size(); ++k) {
        if (d == 3 || k % 3 != 2) x[k] += jitter(rng);
      }
      sim.compute_forces();
      const std::vector<double> f = sim.state().forces;
      const auto& V = model->volumes();
      double sum[3] = {0, 0, 0};
      double scale = 0;
      for (index_t i = 0; i < model->node_count(); ++i) {
        for (int c = 0; c < 3; ++c) {
          sum[c] += f[3 * i + c] * V[i];
          scale = std::max(scale, std::abs(f[3 * i + c] * V[i]));
        }
      }
      for (double s : sum) CHECK(std::abs(s) < 1e-10 * scale * model->node_count());
      for (index_t i : {index_t(0), index_t(7), index_t(model->node_count() / 2)}) {
        for (int c = 0; c < d; ++c) {
          const double step = 1e-8;
          const double saved = x[3 * i + c];
          x[3 * i + c] = saved + step;
          sim.compute_forces();
          const double plus = sim.strain_energy();
          x[3 * i + c] = saved - step;
          sim.compute_forces();
          const double minus = sim.strain_energy();
          x[3 * i + c] = saved;
          const double numeric = -(plus - minus) / (2 * step);
          CHECK(granulate_test::close(numeric, f[3 * i + c] * V[i], 1e-5, 1e-6 * scale));
        }
      }
    }
  }
}

TEST_CASE("lps dilatation of an interior node equals the trace of a homogeneous strain") {
  for (int d : {2, 3}) {
    auto model = lattice_block(d, d == 2 ? 13 : 9, ForceModel::lps, InfluenceKind::linear);
    Simulation sim(model);
    const double strain[3] = {1e-4, -3e-4, d == 3 ? 4e-4 : 0.0};
    auto& x = sim.state().positions;
    for (std::size_t k = 0; k < x.size(); ++k) x[k] *= 1.0 + strain[k % 3];
    sim.compute_forces();
    const int n = d == 2 ? 13 : 9;
    const index_t centre = d == 2 ? index_t(6 * 13 + 6) : index_t((4 * 9 + 4) * 9 + 4);
    (void)n;
    CHECK_CLOSE(sim.state().dilatation[centre], strain[0] + strain[1] + strain[2], 1e-3);
  }
}

namespace {

/// The schedule's invariants: every node in exactly one block, every block in one colour, the
/// blocks of a colour touch disjoint nodes (a node and its forward neighbours, all higher).
void check_schedule(const Model& model) {
  const BondSchedule& s = model.bond_schedule();
  const index_t n = model.node_count();
  CHECK(s.block_starts.front() == 0 && s.block_starts.back() == n);
  CHECK(s.blocks.size() + 1 == s.block_starts.size());
  std::vector<int> block_seen(s.blocks.size(), 0), node_seen(n, 0);
  for (std::size_t c = 0; c + 1 < s.colour_offsets.size(); ++c) {
    std::vector<index_t> owner(n, ~index_t{0});  // the block of this colour touching a node
    for (index_t k = s.colour_offsets[c]; k < s.colour_offsets[c + 1]; ++k) {
      const index_t block = s.blocks[k];
      ++block_seen[block];
      for (index_t i = s.block_starts[block]; i < s.block_starts[block + 1]; ++i) {
        ++node_seen[i];
        const NodeBonds bonds = model.node_bonds(i);
        std::vector<index_t> touched{i};
        for (index_t b = bonds.forward; b < bonds.count; ++b) {
          CHECK(bonds.neighbor(b) > i);
          if (!s.particle_gathers[model.node_particle()[i]]) touched.push_back(bonds.neighbor(b));
        }
        for (index_t b = 0; b < bonds.forward; ++b) CHECK(bonds.neighbor(b) < i);
        for (index_t t : touched) {
          CHECK(owner[t] == ~index_t{0} || owner[t] == block);
          owner[t] = block;
        }
      }
    }
  }
  for (int count : block_seen) CHECK(count == 1);
  for (int count : node_seen) CHECK(count == 1);
}

}  // namespace

TEST_CASE("bond schedule: every node in one block, blocks of a colour touch disjoint nodes") {
  for (int d : {2, 3}) {
    auto model = lattice_block(d, d == 2 ? 60 : 16, ForceModel::lps, InfluenceKind::linear);
    model->finalize();
    check_schedule(*model);
    // Bands of 3 rows (2D) or 3 planes (3D) cut into ranges: each colour has ranges enough for
    // two threads.
    const BondSchedule& s = model->bond_schedule();
    CHECK(s.particle_gathers[0] == 0);
    CHECK(s.blocks.size() >= 4 * (s.colour_offsets.size() - 1));
  }
}

TEST_CASE("bond schedule: a large particle numbered at random gathers, with the same forces") {
  // Ranges of a randomly numbered mesh would each reach across the whole body (a colour each):
  // its nodes gather instead, in parallel blocks of one colour. Forces equal those of the same
  // lattice numbered in order, for the same displaced positions (to round-off: other sums).
  for (int d : {2, 3}) {
    const int side = d == 2 ? 60 : 16;
    std::vector<std::array<double, 3>> nodes;
    for (int k = 0; k < (d == 3 ? side : 1); ++k)
      for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i)
          nodes.push_back({(i + 0.5) * 1e-3, (j + 0.5) * 1e-3, d == 3 ? (k + 0.5) * 1e-3 : 0.0});
    std::vector<std::size_t> shuffled(nodes.size());
    for (std::size_t a = 0; a < nodes.size(); ++a) shuffled[a] = a;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(7));
    auto build = [&](bool random) {
      std::vector<double> x, v;
      for (std::size_t a = 0; a < nodes.size(); ++a) {
        const auto& p = nodes[random ? shuffled[a] : a];
        x.insert(x.end(), p.begin(), p.end());
        v.push_back(d == 3 ? 1e-9 : 1e-6);
      }
      auto model = std::make_shared<Model>(d, PlaneMode::strain);
      model->add_material(granulate_test::test_material());
      model->add_particle(x, v, 0, 1e-3);
      return model;
    };
    auto ordered = build(false), random = build(true);
    Simulation a(ordered), b(random);
    check_schedule(*random);
    const BondSchedule& s = random->bond_schedule();
    CHECK(s.particle_gathers[0] == 1 && ordered->bond_schedule().particle_gathers[0] == 0);
    CHECK(s.colour_offsets.size() == 2 && s.blocks.size() >= 8);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> jitter(-2e-5, 2e-5);
    for (std::size_t q = 0; q < nodes.size(); ++q)
      for (int c = 0; c < d; ++c) a.state().positions[3 * q + c] += jitter(rng);
    for (std::size_t q = 0; q < nodes.size(); ++q)
      for (int c = 0; c < 3; ++c) b.state().positions[3 * q + c] = a.state().positions[3 * shuffled[q] + c];
    a.compute_forces();
    b.compute_forces();
    double scale = 0, worst = 0;
    for (std::size_t q = 0; q < nodes.size(); ++q)
      for (int c = 0; c < 3; ++c) {
        scale = std::max(scale, std::abs(a.state().forces[3 * shuffled[q] + c]));
        worst =
            std::max(worst, std::abs(a.state().forces[3 * shuffled[q] + c] - b.state().forces[3 * q + c]));
      }
    CHECK(scale > 0);
    CHECK(worst < 1e-12 * scale);
  }
}

TEST_CASE("bond schedule: small particles are not cut, so their blocks need one colour") {
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  model->add_material(granulate_test::test_material());
  std::vector<index_t> particle_starts;
  for (int body = 0; body < 200; ++body) {
    particle_starts.push_back(model->node_count());
    granulate_test::add_square(*model, 0, 10, body * 11e-3, 0.0);
  }
  model->finalize();
  check_schedule(*model);
  const BondSchedule& s = model->bond_schedule();
  CHECK(s.colour_offsets.size() == 2);
  CHECK(s.blocks.size() >= 32);
  for (index_t start : s.block_starts) {
    CHECK(start == model->node_count() ||
          std::binary_search(particle_starts.begin(), particle_starts.end(), start));
  }
}

TEST_CASE("bond schedule: a particle is cut by its own bonds, whatever else the model holds") {
  // A distributed run's part holds some of the particles: each must be cut into the same
  // ranges as in the whole model, or its nodes take their terms in another order.
  auto ranges_of_last = [](int others, std::size_t whole) {
    auto model = std::make_shared<Model>(2, PlaneMode::strain);
    model->add_material(granulate_test::test_material());
    model->set_whole_particle_bonds(whole);
    for (int body = 0; body < others; ++body) granulate_test::add_square(*model, 0, 10, body * 11e-3, 0.0);
    const index_t first = model->node_count();
    granulate_test::add_square(*model, 0, 30, -50e-3, 0.0);
    model->finalize();
    check_schedule(*model);
    std::vector<index_t> starts;
    for (index_t start : model->bond_schedule().block_starts)
      if (start >= first) starts.push_back(start - first);
    return starts;
  };
  for (std::size_t whole : {std::size_t{4096}, default_whole_particle_bonds}) {
    const auto alone = ranges_of_last(0, whole);
    CHECK(alone == ranges_of_last(300, whole));
    CHECK((alone.size() > 2) == (whole == 4096));  // 30 x 30 nodes: 4,096-16,384 forward bonds
  }
  Model finished(2, PlaneMode::strain);
  finished.add_material(granulate_test::test_material());
  granulate_test::add_square(finished, 0, 4, 0.0, 0.0);
  finished.finalize();
  CHECK_THROWS(finished.set_whole_particle_bonds(100), InputError);
}

TEST_CASE("bonds break irreversibly at the critical stretch") {
  auto model = lattice_block(2, 8, ForceModel::lps, InfluenceKind::linear, true);
  Simulation sim(model);
  const double s0 = model->materials()[0].critical_stretch;
  auto& x = sim.state().positions;
  for (std::size_t k = 0; k < x.size(); k += 3) x[k] *= 1.0 + 1.5 * s0;  // all x-bonds beyond s0
  sim.compute_forces();
  const auto broken = sim.broken_bonds();
  CHECK(broken > 0);
  for (std::size_t k = 0; k < x.size(); k += 3) x[k] /= 1.0 + 1.5 * s0;  // back to the reference
  sim.compute_forces();
  CHECK(sim.broken_bonds() == broken);
  // A bond breaks at the end that evaluates it; its other copy breaks with it.
  std::uint64_t broken_copies = 0;
  for (index_t i = 0; i < model->node_count(); ++i) {
    const NodeBonds bonds = model->node_bonds(i);
    for (index_t b = 0; b < bonds.count; ++b) {
      const index_t j = bonds.neighbor(b);
      CHECK(sim.state().bonds.intact(i, b) == sim.state().bonds.intact(j, model->node_bonds(j).find(i)));
      if (!sim.state().bonds.intact(i, b)) ++broken_copies;
    }
  }
  CHECK(broken_copies == 2 * broken);
}

TEST_CASE("fragments are the connected components of intact bonds") {
  auto model = lattice_block(2, 12, ForceModel::lps, InfluenceKind::linear, true);
  Simulation sim(model);
  std::vector<index_t> labels(model->node_count());
  CHECK(sim.fragments(labels.data()) == 1);
  // Cut every bond crossing x = 6h: two fragments labelled by their smallest node.
  const auto& X = model->reference_positions();
  for (index_t i = 0; i < model->node_count(); ++i) {
    const NodeBonds b = model->node_bonds(i);
    for (index_t k = 0; k < b.count; ++k) {
      const index_t j = b.neighbor(k);
      if ((X[3 * i] < 6e-3) != (X[3 * j] < 6e-3)) BondStates::clear(sim.state().bonds.node(i), k);
    }
  }
  CHECK(sim.fragments(labels.data()) == 2);
  CHECK(labels[0] == 0);
  CHECK(labels[11] == 6);  // node (11, 0) belongs to the right part, whose smallest node is (6, 0)
  CHECK(labels[12 * 12 - 1] == 6);
}

TEST_CASE("fragments among some nodes are theirs, with the intact bonds that leave them") {
  auto model = lattice_block(2, 12, ForceModel::lps, InfluenceKind::linear, true);
  Simulation sim(model);
  const auto& X = model->reference_positions();
  for (index_t i = 0; i < model->node_count(); ++i) {  // cut across x = 6h, as above
    const NodeBonds b = model->node_bonds(i);
    for (index_t k = 0; k < b.count; ++k) {
      if ((X[3 * i] < 6e-3) != (X[3 * b.neighbor(k)] < 6e-3)) BondStates::clear(sim.state().bonds.node(i), k);
    }
  }
  std::vector<index_t> among;  // the lower half, y < 6h: both sides of the cut
  for (index_t i = 0; i < model->node_count(); ++i)
    if (X[3 * i + 1] < 6e-3) among.push_back(i);
  std::vector<index_t> labels(among.size());
  std::vector<std::array<index_t, 2>> leaving;
  sim.fragments_among(among, labels.data(), leaving);
  std::size_t expected = 0;
  for (std::size_t k = 0; k < among.size(); ++k) {
    CHECK(labels[k] == (X[3 * among[k]] < 6e-3 ? 0u : 6u));
    const NodeBonds b = model->node_bonds(among[k]);
    for (index_t q = 0; q < b.count; ++q)
      if (sim.state().bonds.intact(among[k], q) && X[3 * b.neighbor(q) + 1] >= 6e-3) ++expected;
  }
  CHECK(leaving.size() == expected);
  CHECK(expected > 0);
  for (const auto& [i, j] : leaving) CHECK(X[3 * i + 1] < 6e-3 && X[3 * j + 1] >= 6e-3);
  CHECK_THROWS(sim.fragments_among({5, 3}, labels.data(), leaving), InputError);
}

TEST_CASE("bad particles are refused with InputError") {
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  MaterialParams p;
  p.density = 1000;
  p.bulk_modulus = 1e9;
  p.shear_modulus = 1e9;
  p.horizon = 3e-3;
  p.fracture_energy = 10;
  const index_t material = model->add_material(p);
  const std::vector<double> x = {0, 0, 0, 1e-3, 0, 0};
  CHECK_THROWS(model->add_particle(x, std::vector<double>{1e-6, 0.0}, material, 1e-3), InputError);
  CHECK_THROWS(model->add_particle(x, std::vector<double>{1e-6, 1e-6}, 5, 1e-3), InputError);
  CHECK_THROWS(model->add_particle(x, std::vector<double>{1e-6, 1e-6}, material, 4e-3), InputError);
  CHECK_THROWS(model->add_particle(std::vector<double>{0, 0, 1, 1, 0, 0}, std::vector<double>{1e-6, 1e-6},
                                   material, 1e-3),
               InputError);
  // coincident nodes
  model->add_particle(std::vector<double>{0, 0, 0, 0, 0, 0}, std::vector<double>{1e-6, 1e-6}, material, 1e-3);
  CHECK_THROWS(model->finalize(), InputError);
  // an isolated node
  auto lonely = std::make_shared<Model>(2, PlaneMode::strain);
  lonely->add_material(p);
  lonely->add_particle(std::vector<double>{0, 0, 0, 1e-3, 0, 0, 1, 1, 0},
                       std::vector<double>{1e-6, 1e-6, 1e-6}, 0, 1e-3);
  CHECK_THROWS(lonely->finalize(), InputError);
  CHECK_THROWS(Model(4, PlaneMode::strain), InputError);
}
