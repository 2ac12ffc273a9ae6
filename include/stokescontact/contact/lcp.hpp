#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/lcp/lcp.hpp>.
#include "stokescontact/lcp/lcp.hpp"
