#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/contact/solvers/barrier_nlopt.hpp>.
#include "stokescontact/contact/solvers/barrier_nlopt.hpp"
