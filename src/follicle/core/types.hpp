#pragma once
// Scalar and vector aliases over Eigen. SI units everywhere inside Follicle (metres, seconds,
// kilograms, radians) unless a name says otherwise.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace follicle {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec2f = Eigen::Vector2f;
using Vec3f = Eigen::Vector3f;
using Vec4f = Eigen::Vector4f;
using Vec2i = Eigen::Vector2i;
using Vec3i = Eigen::Vector3i;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat4f = Eigen::Matrix4f;
using Quat = Eigen::Quaterniond;
using Affine3 = Eigen::Affine3d;

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace follicle
