// The state: everything that changes in time.
#pragma once

#include <cstdint>
#include <vector>

#include "granulate/types.hpp"

namespace granulate {

struct State {
  std::vector<real> positions;   ///< x, nodes x 3 [m]
  std::vector<real> velocities;  ///< v, nodes x 3 [m/s]
  std::vector<real> forces;      ///< net force density f, nodes x 3 [N/m^3; per unit volume also in 2D]
  std::vector<std::uint8_t> bond_intact;  ///< per bond copy (see BondFamilies), 1 = intact
  std::vector<real> dilatation;           ///< theta_i of LPS nodes (0 for PMB nodes)
  real time = 0;                          ///< [s]
  std::uint64_t step = 0;
};

}  // namespace granulate
