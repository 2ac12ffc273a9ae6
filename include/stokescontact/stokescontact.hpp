#pragma once
// StokesContact: keeps rigid particles in Stokes flow apart with minimal contact forces.
// Umbrella header: includes every public header, layer by layer.

// core
#include "stokescontact/core/block_average.hpp"
#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/gaussian_stream.hpp"
#include "stokescontact/core/gmres.hpp"
#include "stokescontact/core/lanczos.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/core/types.hpp"

// geometry
#include "stokescontact/geometry/arc_distance.hpp"
#include "stokescontact/geometry/broad_phase.hpp"
#include "stokescontact/geometry/centre_curve.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/geometry/line_contact.hpp"
#include "stokescontact/geometry/mass_tensors.hpp"
#include "stokescontact/geometry/periodic_box.hpp"
#include "stokescontact/geometry/point_distance.hpp"
#include "stokescontact/geometry/primitives.hpp"
#include "stokescontact/geometry/segment_distance.hpp"
#include "stokescontact/geometry/shapes.hpp"
#include "stokescontact/geometry/surface_distances.hpp"
#include "stokescontact/geometry/surface_nodes.hpp"

// mobility
#include "stokescontact/mobility/blob_model.hpp"
#include "stokescontact/mobility/blob_models.hpp"
#include "stokescontact/mobility/blob_rpy.hpp"
#include "stokescontact/mobility/boomerang_blobs.hpp"
#include "stokescontact/mobility/brownian_velocity.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"
#include "stokescontact/mobility/multiblob_mobility.hpp"
#include "stokescontact/mobility/multiblob_saddle_point.hpp"
#include "stokescontact/mobility/pair_mobility_exact.hpp"
#include "stokescontact/mobility/rigidity_matrix.hpp"
#include "stokescontact/mobility/rod_blobs.hpp"
#include "stokescontact/mobility/rpy_kernel.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"
#include "stokescontact/mobility/rpy_rotation_kernel.hpp"
#include "stokescontact/mobility/single_body_mobility.hpp"
#include "stokescontact/mobility/sphere_shell.hpp"
#include "stokescontact/mobility/thermal_drift.hpp"

// scenes: seeded random poses, forces, sphere packings and periodic placement of any shape
#include "stokescontact/scenes/random.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

// lcp (needs only core)
#include "stokescontact/lcp/apgd.hpp"
#include "stokescontact/lcp/bbpgd.hpp"
#include "stokescontact/lcp/lcp.hpp"
#include "stokescontact/lcp/minimum_map_newton.hpp"

// contact: detection, the contact matrix, the contact step
#include "stokescontact/contact/barrier.hpp"
#include "stokescontact/contact/contact_matrix.hpp"
#include "stokescontact/contact/contact_pairs.hpp"
#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/d_try.hpp"
#include "stokescontact/contact/scene.hpp"
#include "stokescontact/contact/surface_contacts.hpp"

// contact/solvers: the contact-step solvers and the choice among them
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/contact/solvers/delassus_probing.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#include "stokescontact/contact/solvers/secant_update.hpp"
#if STOKESCONTACT_HAS_NLOPT
#include "stokescontact/contact/solvers/barrier_nlopt.hpp"
#endif

// dynamics
#include "stokescontact/dynamics/background_flow.hpp"
#include "stokescontact/dynamics/collision_stress.hpp"
#include "stokescontact/dynamics/nematic_order.hpp"
#include "stokescontact/dynamics/step_diagnostics.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"

// io
#include "stokescontact/io/body_mesh.hpp"
#include "stokescontact/io/checkpoint.hpp"
#include "stokescontact/io/diagnostics_json.hpp"
#include "stokescontact/io/json.hpp"
#include "stokescontact/io/vtk_polydata.hpp"
