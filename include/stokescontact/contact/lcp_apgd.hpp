#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/lcp/apgd.hpp>.
#include "stokescontact/lcp/apgd.hpp"
