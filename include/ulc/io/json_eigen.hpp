// Eigen matrices and transforms <-> JSON arrays (row-major nested arrays), with checked reads.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "ulc/io/json.hpp"

namespace ulc::io {

/// A matrix as an array of rows.
template <typename Derived>
Json matrix_to_json(const Eigen::MatrixBase<Derived>& m) {
  Json rows = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(static_cast<double>(m(r, c)));
    rows.push_back(std::move(row));
  }
  return rows;
}

/// A vector as a flat array.
template <typename Derived>
Json vector_to_json(const Eigen::MatrixBase<Derived>& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(static_cast<double>(v(i)));
  return out;
}

/// Reads a Rows x Cols matrix of finite numbers; `what` names the field in errors.
template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> json_to_matrix(const Json& j, const std::string& file,
                                                 const std::string& what) {
  Eigen::Matrix<double, Rows, Cols> m;
  if (!j.is_array() || j.size() != Rows)
    throw IoError(file, what, "expected an array of " + std::to_string(Rows) + " rows");
  for (int r = 0; r < Rows; ++r) {
    const Json& row = j[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != Cols)
      throw IoError(file, what,
                    "row " + std::to_string(r) + " must hold " + std::to_string(Cols) + " numbers");
    for (int c = 0; c < Cols; ++c) {
      const Json& v = row[static_cast<std::size_t>(c)];
      if (!v.is_number() || !std::isfinite(v.as_number()))
        throw IoError(
            file, what,
            "non-numeric entry at row " + std::to_string(r) + ", column " + std::to_string(c));
      m(r, c) = v.as_number();
    }
  }
  return m;
}

/// Reads a 4x4 rigid transform; its rotation block must be a rotation (orthonormal, det +1)
/// within 1e-3 and its last row [0 0 0 1]; the rotation is re-orthonormalised.
inline Eigen::Isometry3d json_to_isometry(const Json& j, const std::string& file,
                                          const std::string& what) {
  const Eigen::Matrix4d m = json_to_matrix<4, 4>(j, file, what);
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-3 || r.determinant() < 0)
    throw IoError(file, what, "the 3x3 block is not a rotation matrix");
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
    throw IoError(file, what, "the last row must be [0, 0, 0, 1]");
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = svd.matrixU() * svd.matrixV().transpose();
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

}  // namespace ulc::io
