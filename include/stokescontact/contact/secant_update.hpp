#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/contact/solvers/secant_update.hpp>.
#include "stokescontact/contact/solvers/secant_update.hpp"
