#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/lcp/minimum_map_newton.hpp>.
#include "stokescontact/lcp/minimum_map_newton.hpp"
