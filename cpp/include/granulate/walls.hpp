// Rigid kinematic walls: surfaces (plane, box, circle/cylinder, polygon), moved as one body by a
// translation or a rotation given by a time function. Node-wall contact uses contact_law.hpp
// with the distance from the node to the surface.
#pragma once

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "granulate/loading.hpp"
#include "granulate/types.hpp"

namespace granulate {

/// One surface of a wall, in the wall's reference frame (its position at t = 0).
///   plane:          point, normal (unit, pointing into the region where particles are)
///   box_inside:     lower, upper; particles inside (each face is a plane)
///   box_outside:    lower, upper; particles outside (an obstacle)
///   circle_inside:  center, radius, axis; particles inside a circle (2D) or cylinder (3D)
///   circle_outside: the same, particles outside (a post, a roller)
///   polygon:        vertices (2D, in order), particles inside when inside == true
///   triangles:      a triangle mesh (3D): mesh_vertices, mesh_triangles; each triangle's normal
///                   (right-hand rule) points away from the particles when inside == true (a
///                   closed container with outward normals, as STL files have), towards them
///                   when inside == false (an obstacle)
struct WallSurface {
  enum class Kind : std::uint8_t {
    plane,
    box_inside,
    box_outside,
    circle_inside,
    circle_outside,
    polygon,
    triangles
  };
  Kind kind = Kind::plane;
  std::array<real, 3> point{0, 0, 0};   ///< plane point, circle centre
  std::array<real, 3> normal{0, 1, 0};  ///< plane normal; circle/cylinder axis
  std::array<real, 3> lower{0, 0, 0};
  std::array<real, 3> upper{0, 0, 0};
  real radius = 0;
  std::vector<std::array<real, 2>> vertices;  ///< polygon
  bool inside = true;                         ///< polygon, triangles: particles inside
  std::vector<std::array<real, 3>> mesh_vertices;
  std::vector<std::array<index_t, 3>> mesh_triangles;

  /// Uniform grid of polygon edge bounding boxes and horizontal bands of their heights (built
  /// by Wall::validate): a point's nearest edge within a reach is sought among the edges of
  /// the cells that reach covers, and whether it is inside among the edges of its band.
  struct EdgeGrid {
    std::array<real, 2> origin{0, 0};
    real cell_size = 1;
    std::array<std::int64_t, 2> dims{1, 1};
    std::vector<index_t> cell_start, cell_edges;    ///< edge a joins vertices a and a + 1
    real lowest = 0, highest = 0, band_height = 1;  ///< the vertices' heights, bands over them
    std::int64_t bands = 1;
    std::vector<index_t> band_start, band_edges;
    /// The cell of coordinate x along axis k, clamped to the grid (0 for nan).
    std::int64_t cell_of(real x, int k) const { return clamped((x - origin[k]) / cell_size, dims[k]); }
    /// The band of height y, clamped to the bands (0 for nan).
    std::int64_t band_of(real y) const { return clamped((y - lowest) / band_height, bands); }
    static std::int64_t clamped(real place, std::int64_t count) {
      if (!(place > 0)) return 0;
      return static_cast<std::int64_t>(std::min(place, static_cast<real>(count - 1)));
    }
  } edge_grid;

  /// Uniform grid of triangle bounding boxes (built by Wall::validate) for closest-point queries.
  struct TriangleGrid {
    std::array<real, 3> origin{0, 0, 0};
    real cell_size = 1;
    std::array<std::int64_t, 3> dims{1, 1, 1};
    std::vector<index_t> cell_start, cell_triangles;
  } grid;
};

/// Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5).
std::array<real, 3> closest_point_on_triangle(const std::array<real, 3>& p, const std::array<real, 3>& a,
                                              const std::array<real, 3>& b, const std::array<real, 3>& c);

/// A contact candidate between a point and a surface: signed distance (positive on the
/// particles' side) and the unit normal pointing from the surface towards the particles.
struct WallContact {
  real distance = 0;
  std::array<real, 3> normal{0, 0, 0};
};

/// Signed distance from p to a polygon surface's boundary, positive outside the polygon, and the
/// outward normal of its closest point (2D, z ignored), over every edge: what Wall::contacts
/// gives of the edges its grid offers, before the sign of a container (inside == true).
WallContact polygon_distance(const WallSurface& s, const std::array<real, 3>& p);

struct Wall {
  enum class Motion : std::uint8_t { fixed, translation, rotation };
  std::string name;
  std::vector<WallSurface> surfaces;
  Motion motion = Motion::fixed;
  std::array<real, 3> direction{1, 0, 0};  ///< translation: x = X + f(t) direction
  std::array<real, 3> center{0, 0, 0};     ///< rotation centre; also the torque reference point
  std::array<real, 3> axis{0, 0, 1};       ///< rotation axis (unit)
  TimeFunction function;                   ///< displacement [m] or angle [rad]
  real extent = 0;  ///< largest distance of the wall's finite features from `center` (set by validate)

  /// Throws InputError for meaningless geometry; normalises directions.
  void validate(int dimension);

  /// Maps a world point at time t into the reference frame (undoes the motion).
  std::array<real, 3> to_reference(const real* x, real t) const;
  /// Maps a reference-frame vector to the world frame at time t.
  std::array<real, 3> rotate_to_world(const std::array<real, 3>& v, real t) const;
  /// Velocity of the wall's material point at world position x, time t.
  std::array<real, 3> velocity_at(const real* x, real t) const;
  /// Angular velocity of the wall at time t [rad/s] (zero unless it rotates).
  std::array<real, 3> angular_velocity(real t) const;
  /// Largest distance any wall point has moved between times t0 and t1 (bound) [m].
  real motion_bound(real t0, real t1) const;

  /// Contacts of a reference-frame point with surface s within `reach` (appends to out).
  void contacts(std::size_t surface, const std::array<real, 3>& p, real reach, int dimension,
                std::vector<WallContact>& out) const;
};

}  // namespace granulate
