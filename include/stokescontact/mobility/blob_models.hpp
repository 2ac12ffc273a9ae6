#pragma once
// Every blob model shipped: sphere shells, rods, boomerangs (one header each).
#include "stokescontact/mobility/blob_model.hpp"
#include "stokescontact/mobility/boomerang_blobs.hpp"
#include "stokescontact/mobility/rod_blobs.hpp"
#include "stokescontact/mobility/sphere_shell.hpp"
