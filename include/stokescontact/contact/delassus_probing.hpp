#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/contact/solvers/delassus_probing.hpp>.
#include "stokescontact/contact/solvers/delassus_probing.hpp"
