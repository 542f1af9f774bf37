// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace armdyn {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;  ///< Euler parameters, scalar-first [e0, e1, e2, e3]
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat4 = Eigen::Matrix4d;                            ///< homogeneous transform [R p; 0 1]
using Mat6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;  ///< a Jacobian of [v; w]
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
using Mat3x12 = Eigen::Matrix<double, 3, 12>;
using Row12 = Eigen::Matrix<double, 1, 12>;

}  // namespace armdyn
