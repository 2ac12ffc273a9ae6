#pragma once
// StokesContact: keeps rigid particles in Stokes flow apart with minimal contact forces.
// Umbrella header: includes every public header, layer by layer.

// core
#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/core/types.hpp"

// geometry
#include "stokescontact/geometry/broad_phase.hpp"
#include "stokescontact/geometry/centre_curve.hpp"
#include "stokescontact/geometry/mass_tensors.hpp"
#include "stokescontact/geometry/point_distance.hpp"
#include "stokescontact/geometry/primitives.hpp"
#include "stokescontact/geometry/shapes.hpp"
#include "stokescontact/geometry/surface_nodes.hpp"

// mobility
#include "stokescontact/mobility/mobility_operator.hpp"
#include "stokescontact/mobility/rpy_kernel.hpp"

// io
#include "stokescontact/io/json.hpp"
