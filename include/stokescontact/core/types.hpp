#pragma once
// Eigen aliases used throughout the library.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace stokescontact {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Vec7 = Eigen::Matrix<double, 7, 1>;
using Mat3X = Eigen::Matrix3Xd;
using VecX = Eigen::VectorXd;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using MatX = Eigen::MatrixXd;

}  // namespace stokescontact
