// Contact law sub-models, walls' distance queries, Newton's third law of node contacts.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>

#include "check.hpp"
#include "fixtures.hpp"
#include "granulate/contact/collisions.hpp"
#include "granulate/contact/power_law_damping.hpp"
#include "granulate/simulation.hpp"

using namespace granulate;

TEST_CASE("damping ratio from restitution: e = exp(-pi zeta / sqrt(1 - zeta^2))") {
  for (double e : {0.2, 0.5, 0.8, 0.95}) {
    const double zeta = contact::damping_ratio_from_restitution(e);
    CHECK_CLOSE(std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta)), e, 1e-12);
  }
  CHECK(contact::damping_ratio_from_restitution(1.0) == 0.0);
}

TEST_CASE("power-law collisions whose force never pulls: stiffer laws rebound more, the inverse") {
  // The references come from an independent integration of x'' = -max(0, x^p + 2 zeta
  // x^((p-1)/2) x') (RK4, dt = 2e-4, in Python, printed to 4 digits) with the linear zeta of
  // e; unclipped, p = 1 gives e itself (and p = 1.5, 2: 0.1413 and 0.1770 for e = 0.1).
  const double e[5] = {0.1, 0.3, 0.5, 0.7, 0.9};
  const double linear[5] = {0.2527, 0.3971, 0.5503, 0.7182, 0.9020};
  const double hertz[5] = {0.2828, 0.4312, 0.5823, 0.7422, 0.9117};
  const double square[5] = {0.3084, 0.4590, 0.6076, 0.7607, 0.9190};
  for (int k = 0; k < 5; ++k) {
    const double zeta = contact::damping_ratio_from_restitution(e[k]);
    CHECK_CLOSE(contact::power_law_restitution(zeta, 1.0), linear[k], 1e-3);  // relative
    CHECK_CLOSE(contact::power_law_restitution(zeta, 1.5), hertz[k], 1e-3);
    CHECK_CLOSE(contact::power_law_restitution(zeta, 2.0), square[k], 1e-3);
    const double fitted_linear = contact::power_law_damping_ratio(e[k], 1.0);
    const double fitted = contact::power_law_damping_ratio(e[k], 2.0);
    CHECK(fitted_linear > zeta && fitted > fitted_linear);
    CHECK_CLOSE(contact::power_law_restitution(fitted_linear, 1.0), e[k], 1e-4);
    CHECK_CLOSE(contact::power_law_restitution(fitted, 2.0), e[k], 1e-4);
    const contact::DampingTable table(zeta);
    CHECK_CLOSE(table.at(1.0), fitted_linear, 1e-4);
    CHECK(table.at(0.5) == table.at(1.0));
    CHECK_CLOSE(table.at(2.0), fitted, 1e-4);
  }
  CHECK(contact::power_law_restitution(0.0, 2.0) > 0.999);
  CHECK(contact::power_law_damping_ratio(1.0, 2.0) == 0.0);
}

TEST_CASE("damping tables made as collisions need them hold the entries made all at once") {
  // Each entry bracketed from the one before (power_law_damping.hpp), as the eager table made
  // them; asked from four threads at once, from the largest exponent down, a restitution not
  // asked before (0.37) gives those entries: at their exponents, and between them to round-off
  // (an entry bracketed otherwise would differ by up to the search's 1e-6).
  const real zeta = contact::damping_ratio_from_restitution(0.37);
  std::array<real, contact::DampingTable::size> expected{};
  const real restitution = std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta));
  expected[0] = contact::power_law_damping_ratio(restitution, 1.0, zeta, 2 * zeta + 1e-3);
  for (int k = 1; k < contact::DampingTable::size; ++k)
    expected[k] = contact::power_law_damping_ratio(restitution, 1.0 + 0.1 * k, expected[k - 1],
                                                   1.5 * expected[k - 1] + 1e-3);
  const contact::DampingTable table(zeta);
  std::array<real, 81> asked{};
#pragma omp parallel for num_threads(4)
  for (int k = 80; k >= 0; --k) asked[k] = table.at(1.0 + 0.025 * k);
  for (int k = 0; k < 81; ++k) {
    const int below = std::min(k / 4, 19);
    const real share = 0.25 * (k - 4 * below);
    CHECK_CLOSE(asked[k], (1 - share) * expected[below] + share * expected[below + 1], 1e-13);
  }
  CHECK(table.at(1.0) == expected[0] && table.at(3.0) == expected[20]);
  CHECK(contact::DampingTable().at(2.0) == 0.0);
}

TEST_CASE("the friction spring sticks below mu F_n, slides at it, turns with the normal, is odd") {
  const real normal[3] = {0, 1, 0}, slip[3] = {2.0, 0.5, 0}, dt = 1e-3;
  real shear[3] = {0, 0, 0}, force[3];
  // Stick: xi = v_t dt (the normal part of the slip is dropped), F = -kt xi.
  contact::tangential_force(100.0, 0.5, 10.0, normal, slip, dt, shear, force);
  CHECK_CLOSE(shear[0], 2e-3, 1e-15);
  CHECK(shear[1] == 0.0 && shear[2] == 0.0);
  CHECK_CLOSE(force[0], -0.2, 1e-14);
  // Sliding: the spring would carry 100 x 0.502 = 50.2 > mu F_n = 5, so it is shortened to 5.
  shear[0] = 0.5;
  contact::tangential_force(100.0, 0.5, 10.0, normal, slip, dt, shear, force);
  CHECK_CLOSE(force[0], -5.0, 1e-14);
  CHECK_CLOSE(shear[0], 0.05, 1e-15);
  // A turned normal: the spring is turned into the new tangent plane, keeping its length.
  const real turned[3] = {std::sqrt(0.5), std::sqrt(0.5), 0}, still[3] = {0, 0, 0};
  real kept[3] = {0.01, 0, 0};
  contact::tangential_force(100.0, 0.5, 10.0, turned, still, dt, kept, force);
  CHECK_CLOSE(std::hypot(kept[0], kept[1]), 0.01, 1e-15);
  CHECK(std::abs(kept[0] * turned[0] + kept[1] * turned[1]) < 1e-17);
  // The other entry of the pair (normal, slip and spring negated) computes exactly -force.
  real mine[3] = {3e-4, 0, 1e-4}, theirs[3] = {-3e-4, -0.0, -1e-4}, mine_force[3], their_force[3];
  const real n2[3] = {0.6, 0.8, 0}, n2_back[3] = {-0.6, -0.8, -0.0};
  const real s2[3] = {0.3, -0.2, 0.7}, s2_back[3] = {-0.3, 0.2, -0.7};
  contact::tangential_force(100.0, 0.3, 2.0, n2, s2, dt, mine, mine_force);
  contact::tangential_force(100.0, 0.3, 2.0, n2_back, s2_back, dt, theirs, their_force);
  for (int k = 0; k < 3; ++k) CHECK(mine_force[k] == -their_force[k] && mine[k] == -theirs[k]);
}

TEST_CASE("the rolling spring holds below mu_r R* F_n, rolls at it (and says so), ignores torsion") {
  const real normal[3] = {0, 1, 0}, spin[3] = {0, 3.0, -2.0}, dt = 1e-3;  // spin: torsion 3, roll -2
  real rotation[3] = {0, 0, 0}, torque[3];
  // Holds: theta = omega_roll dt (the torsion about the normal is dropped), M = -k_r theta.
  CHECK(!contact::rolling_torque(50.0, 0.2, 0.1, 10.0, normal, spin, dt, rotation, torque));
  CHECK(rotation[1] == 0.0 && rotation[0] == 0.0);
  CHECK_CLOSE(rotation[2], -2e-3, 1e-18);
  CHECK_CLOSE(torque[2], 0.1, 1e-15);
  // Rolls: 50 x 1.002 > mu_r R* F_n = 0.2, so the torque is capped there.
  rotation[2] = -1.0;
  CHECK(contact::rolling_torque(50.0, 0.2, 0.1, 10.0, normal, spin, dt, rotation, torque));
  CHECK_CLOSE(torque[2], 0.2, 1e-15);
  CHECK_CLOSE(rotation[2], -4e-3, 1e-15);
}

TEST_CASE("collision records: opened on demand, reused once closed, carried by renumbering") {
  contact::CollisionStore store;
  store.reset(4);
  CHECK(store.find(2) == nullptr && store.get(2) == contact::Collision{} && store.approach(2) == 0);
  store.open(1).approach = 1e-6;
  store.open(3).work = 2.0;
  CHECK(store.open_count() == 2 && store.approach(1) == 1e-6 && store.get(3).work == 2.0);
  store.close(1);
  store.close(1);  // closing twice is harmless
  CHECK(store.find(1) == nullptr && store.open_count() == 1);
  CHECK(store.open(0) == contact::Collision{});  // a reused record starts as no collision
  // New slots 0..2 are old slots 3, none and 0; old slot 1 has no record to carry.
  store.open(0).approach = 5e-7;
  store.renumber({3, contact::CollisionStore::none, 0});
  CHECK(store.slot_count() == 3 && store.open_count() == 2);
  CHECK(store.get(0).work == 2.0 && store.find(1) == nullptr && store.approach(2) == 5e-7);
}

TEST_CASE("relative contact laws resolve per pair, symmetrically, from the finer particle") {
  contact::Law law;
  law.contact_radius_factor = 0.95;
  law.stiffness_factor = 2.0;
  const contact::ContactSide fine{1e-3, 3e-3, 1e9}, coarse{2e-3, 6e-3, 3e9};
  for (int dimension : {2, 3}) {
    const contact::PairLaw ab = contact::resolve(law, fine, coarse, dimension);
    const contact::PairLaw ba = contact::resolve(law, coarse, fine, dimension);
    CHECK(ab.contact_radius == ba.contact_radius && ab.normal_stiffness == ba.normal_stiffness);
    // Each node's contact radius is 0.95 h / 2 of its own particle: Rc = 0.95 (1 + 2) mm / 2.
    CHECK_CLOSE(ab.contact_radius, 1.425e-3, 1e-15);
    CHECK_CLOSE(contact::resolve_wall(law, coarse, dimension).contact_radius, 0.95e-3, 1e-15);
    law.node_pair = true;  // PeriDEM's law: the finer mesh size, for pairs and walls
    CHECK_CLOSE(contact::resolve(law, coarse, fine, dimension).contact_radius, 0.95e-3, 1e-15);
    CHECK_CLOSE(contact::resolve_wall(law, coarse, dimension).contact_radius, 1.9e-3, 1e-15);
    law.node_pair = false;
    const double effective = 2 * 1e9 * 3e9 / 4e9;
    const double expected = dimension == 3 ? 2 * 18 * effective / (std::numbers::pi * std::pow(3e-3, 5))
                                           : 2 * 12 * effective / (std::numbers::pi * std::pow(3e-3, 4));
    CHECK_CLOSE(ab.normal_stiffness, expected, 1e-12);
  }
  // Same mesh size: the smaller horizon decides, whichever side it is on.
  const contact::ContactSide wide{1e-3, 4e-3, 1e9};
  CHECK(contact::resolve(law, fine, wide, 3).normal_stiffness ==
        contact::resolve(law, wide, fine, 3).normal_stiffness);
  CHECK_CLOSE(contact::resolve(law, wide, fine, 3).normal_stiffness,
              2 * 18 * 1e9 / (std::numbers::pi * std::pow(3e-3, 5)), 1e-12);
  // Absolute values win over factors.
  law.contact_radius = 5e-4;
  law.normal_stiffness = 7.0;
  const contact::PairLaw absolute = contact::resolve(law, fine, coarse, 3);
  CHECK(absolute.contact_radius == 5e-4 && absolute.normal_stiffness == 7.0);
}

TEST_CASE("wall distance queries: plane, box, circle, polygon") {
  Wall wall;
  wall.name = "w";
  WallSurface plane;
  plane.kind = WallSurface::Kind::plane;
  plane.point = {0, 1, 0};
  plane.normal = {0, 2, 0};
  WallSurface box;
  box.kind = WallSurface::Kind::box_inside;
  box.lower = {0, 0, 0};
  box.upper = {4, 2, 0};
  WallSurface circle;
  circle.kind = WallSurface::Kind::circle_outside;
  circle.point = {10, 0, 0};
  circle.radius = 1;
  WallSurface polygon;
  polygon.kind = WallSurface::Kind::polygon;
  polygon.vertices = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  polygon.inside = true;
  wall.surfaces = {plane, box, circle, polygon};
  wall.validate(2);
  std::vector<WallContact> out;
  wall.contacts(0, {3, 1.25, 0}, 1.0, 2, out);
  CHECK(out.size() == 1 && std::abs(out[0].distance - 0.25) < 1e-15 && out[0].normal[1] == 1.0);
  out.clear();
  wall.contacts(1, {0.1, 1.95, 0}, 0.2, 2, out);  // near the left and top faces
  CHECK(out.size() == 2);
  out.clear();
  wall.contacts(2, {12, 0, 0}, 2.0, 2, out);
  CHECK(out.size() == 1 && std::abs(out[0].distance - 1.0) < 1e-15 && out[0].normal[0] == 1.0);
  out.clear();
  wall.contacts(3, {1.9, 1.0, 0}, 0.5, 2, out);  // inside the square, 0.1 from the right edge
  CHECK(out.size() == 1 && std::abs(out[0].distance - 0.1) < 1e-12 &&
        std::abs(out[0].normal[0] + 1.0) < 1e-15);
  out.clear();
  wall.contacts(3, {2.5, 1.0, 0}, 0.5, 2, out);  // outside: negative distance (penetration)
  CHECK(out.size() == 1 && std::abs(out[0].distance + 0.5) < 1e-12);
}

namespace {

/// A floor of saw teeth (120 teeth, 0.3 high at a pitch of 1, tips at y = 0, closed 0.6 below)
/// or a star of 200 points: polygons of many short edges and a few long ones.
std::vector<std::array<real, 2>> many_edged_polygon(bool teeth) {
  std::vector<std::array<real, 2>> v;
  if (teeth) {
    for (int k = 0; k <= 240; ++k) v.push_back({0.5 * k, k % 2 == 0 ? 0.0 : -0.3});
    v.push_back({120.0, -0.6});
    v.push_back({0.0, -0.6});
    return v;
  }
  for (int k = 0; k < 400; ++k) {
    const real angle = 2 * std::numbers::pi * k / 400, radius = k % 2 == 0 ? 10.0 : 9.0;
    v.push_back({3 + radius * std::cos(angle), -1 + radius * std::sin(angle)});
  }
  return v;
}

}  // namespace

TEST_CASE("polygon walls: the edge grid's contacts are every edge's, bit for bit") {
  // Random points near and far, inside and outside, obstacles and containers, small and large
  // reaches: Wall::contacts (the grid's nearest edge) against polygon_distance (every edge),
  // with the sign a container turns and the reach the caller keeps.
  std::mt19937 rng(11);
  int compared = 0, kept = 0;
  for (const bool teeth : {true, false}) {
    for (const bool inside : {false, true}) {
      Wall wall;
      wall.name = "w";
      WallSurface polygon;
      polygon.kind = WallSurface::Kind::polygon;
      polygon.vertices = many_edged_polygon(teeth);
      polygon.inside = inside;
      wall.surfaces = {polygon};
      wall.validate(2);
      std::uniform_real_distribution<real> x(teeth ? -5 : -12, teeth ? 125 : 18),
          y(teeth ? -3 : -16, teeth ? 2 : 14);
      for (int k = 0; k < 20000; ++k) {
        const std::array<real, 3> p{x(rng), y(rng), 0};
        const real reach = std::array<real, 3>{0.05, 0.4, 3.0}[k % 3];
        std::vector<WallContact> out;
        wall.contacts(0, p, reach, 2, out);
        WallContact every = polygon_distance(wall.surfaces[0], p);
        if (inside) {
          every.distance = -every.distance;
          for (real& c : every.normal) c = -c;
        }
        const bool expected = every.distance < reach && (every.normal[0] != 0 || every.normal[1] != 0);
        CHECK(out.size() == (expected ? 1u : 0u));
        if (expected && out.size() == 1) {
          CHECK(out[0].distance == every.distance && out[0].normal == every.normal);
          ++kept;
        }
        ++compared;
      }
    }
  }
  CHECK(compared == 80000 && kept > 8000);
}

TEST_CASE("moving walls: reference frame and surface velocity") {
  Wall wall;
  wall.name = "drum";
  WallSurface circle;
  circle.kind = WallSurface::Kind::circle_inside;
  circle.radius = 1;
  wall.surfaces = {circle};
  wall.motion = Wall::Motion::rotation;
  wall.function = {TimeFunction::Kind::linear, 2.0, 0};  // 2 rad/s
  wall.validate(2);
  const real x[3] = {1, 0, 0};
  const auto v = wall.velocity_at(x, 0.3);
  CHECK_CLOSE(v[1], 2.0, 1e-15);
  const auto p = wall.to_reference(x, std::numbers::pi / 4);  // rotated back by 90 degrees
  CHECK(std::abs(p[0]) < 1e-15 && std::abs(p[1] + 1.0) < 1e-15);
  CHECK_CLOSE(wall.motion_bound(0, std::numbers::pi / 4), 2 * std::sin(std::numbers::pi / 4), 1e-12);
}

TEST_CASE("node contact forces obey Newton's third law to round-off") {
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  model->add_material(granulate_test::test_material());
  for (int body = 0; body < 2; ++body) granulate_test::add_square(*model, 0, 6, body * 6.5e-3, body * 0.3e-3);
  Simulation sim(model);
  contact::Law law;
  law.contact_radius = 0.95e-3;
  law.normal_stiffness = 1e20;
  law.damping_ratio = 0.3;
  law.friction = 0.4;
  sim.contact().set_law(0, 0, law);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> speed(-1, 1);
  for (auto& c : sim.state().velocities) c = speed(rng);
  for (std::size_t k = 2; k < sim.state().velocities.size(); k += 3) sim.state().velocities[k] = 0;
  sim.state().positions[3 * 36] -= 1.3e-3;  // push a node of body 1 into body 0
  sim.compute_forces();
  // Contact forces alone: subtract the peridynamic forces of a contact-free copy.
  Simulation free(model);
  free.state().positions = sim.state().positions;
  free.compute_forces();
  double sum[3] = {0, 0, 0}, scale = 0;
  for (index_t i = 0; i < model->node_count(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double contact_force = (sim.state().forces[3 * i + c] - free.state().forces[3 * i + c]) * 1e-6;
      sum[c] += contact_force;
      scale = std::max(scale, std::abs(contact_force));
    }
  }
  CHECK(scale > 0);
  CHECK(sim.contact().statistics().node_contacts > 0);
  for (double s : sum) CHECK(std::abs(s) < 1e-12 * scale);
}

TEST_CASE("closest point on a triangle: face, edge and vertex regions") {
  const std::array<real, 3> a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  const auto face = closest_point_on_triangle({0.2, 0.3, 5.0}, a, b, c);
  CHECK(std::abs(face[0] - 0.2) < 1e-15 && std::abs(face[1] - 0.3) < 1e-15 && face[2] == 0.0);
  const auto edge = closest_point_on_triangle({0.5, -2.0, 1.0}, a, b, c);
  CHECK(std::abs(edge[0] - 0.5) < 1e-15 && edge[1] == 0.0 && edge[2] == 0.0);
  const auto vertex = closest_point_on_triangle({2.0, -1.0, 0.0}, a, b, c);
  CHECK(vertex == b);
  const auto hypotenuse = closest_point_on_triangle({1.0, 1.0, 0.0}, a, b, c);
  CHECK(std::abs(hypotenuse[0] - 0.5) < 1e-15 && std::abs(hypotenuse[1] - 0.5) < 1e-15);
}

TEST_CASE("triangle-mesh wall: signed distance and normal towards the particles") {
  // A unit cube with outward normals (right-hand rule), particles inside.
  Wall wall;
  wall.name = "cube";
  WallSurface mesh;
  mesh.kind = WallSurface::Kind::triangles;
  mesh.mesh_vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                        {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  mesh.mesh_triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                         {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {0, 4, 7}, {0, 7, 3}};
  mesh.inside = true;
  wall.surfaces = {mesh};
  wall.validate(3);
  std::vector<WallContact> out;
  wall.contacts(0, {0.5, 0.5, 0.1}, 0.2, 3, out);  // 0.1 above the floor, inside
  CHECK(out.size() == 1 && std::abs(out[0].distance - 0.1) < 1e-12 &&
        std::abs(out[0].normal[2] - 1.0) < 1e-12);
  out.clear();
  wall.contacts(0, {0.5, 0.5, -0.05}, 0.2, 3, out);  // below the floor: penetrated
  CHECK(out.size() == 1 && std::abs(out[0].distance + 0.05) < 1e-12 &&
        std::abs(out[0].normal[2] - 1.0) < 1e-12);
  out.clear();
  wall.contacts(0, {0.5, 0.5, 0.5}, 0.2, 3, out);  // the centre is far from every face
  CHECK(out.empty());
  Wall degenerate = wall;
  degenerate.surfaces[0].mesh_triangles.push_back({0, 1, 1});
  CHECK_THROWS(degenerate.validate(3), InputError);
}

TEST_CASE("lists updated after bond breaks hold every unbonded pair within Rc") {
  // A brittle plate whose halves are driven into each other at 60 m/s: bonds break over many
  // steps (3,001 here), mostly while nothing has moved half the skin, so the lists are updated
  // (the newly unbonded pairs inserted: 102 updates, 29 rebuilds). At every step, every pair of
  // nodes without an intact bond closer than Rc must be listed (86,452 such pairs seen).
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  model->add_material(granulate_test::test_material(0.01));
  const int n = 16;
  granulate_test::add_square(*model, 0, n, 0.0, 0.0);
  Simulation sim(model);
  contact::Law law;
  law.contact_radius = 0.9e-3;
  law.normal_stiffness = 1e18;
  law.damping_ratio = 0.1;
  sim.contact().set_law(0, 0, law);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  auto& velocity = sim.state().velocities;
  for (index_t i = 0; i < model->node_count(); ++i) {
    const double side = model->reference_positions()[3 * i] < n * 0.5e-3 ? -1.0 : 1.0;
    velocity[3 * i] = -side * 30.0 + jitter(rng);
    velocity[3 * i + 1] = jitter(rng);
  }
  sim.set_time_step(0.5 * sim.stable_time_step());
  const auto& X = sim.state().positions;
  std::size_t missing = 0, close_unbonded = 0;
  for (int step = 0; step < 300; ++step) {
    sim.run(1);
    const ContactCheckpoint lists = sim.contact().checkpoint();
    for (index_t i = 0; i < model->node_count(); ++i) {
      const NodeBonds bonds = model->node_bonds(i);
      for (index_t j = 0; j < model->node_count(); ++j) {
        if (j == i || std::hypot(X[3 * j] - X[3 * i], X[3 * j + 1] - X[3 * i + 1]) >= law.contact_radius)
          continue;
        const index_t b = bonds.find(j);
        if (b != bonds.count && sim.state().bonds.intact(i, b)) continue;
        ++close_unbonded;
        const auto begin = lists.pair_partners.begin() + lists.pair_offsets[i];
        const auto end = lists.pair_partners.begin() + lists.pair_offsets[i + 1];
        if (!std::binary_search(begin, end, j)) ++missing;
      }
    }
  }
  CHECK(sim.broken_bonds() > 1000);
  CHECK(sim.contact().statistics().list_updates > 20);
  CHECK(close_unbonded > 0);
  CHECK(missing == 0);
}
