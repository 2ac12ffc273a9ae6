#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/lcp/bbpgd.hpp>.
#include "stokescontact/lcp/bbpgd.hpp"
