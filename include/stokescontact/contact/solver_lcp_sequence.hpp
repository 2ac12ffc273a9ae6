#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/contact/solvers/lcp_sequence.hpp>.
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
