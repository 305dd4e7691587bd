// ULC's JSON files (ground_truth.json, result files) with nlohmann::json (Debian's
// nlohmann-json3-dev): component ulc::results, not ulc::ulc (cmake/UlcResults.cmake).
//
// Json is nlohmann::ordered_json, so written files keep their keys in insertion order (stable,
// diffable). Numbers are written as nlohmann writes them: the shortest text that reads back to
// the same double (a round trip is exact); NaN and infinity are written as null. Strings that are
// not valid UTF-8 (a recording's frame_id, say) are written with U+FFFD for the bad bytes.
//
// The layout is ours (write_json_file, dump_json), measured: nlohmann's pretty printer puts every
// number on its own line, so a 4x4 matrix takes 26 lines and each [offset, spread] point of
// HOTS's curve 4; here an array of numbers or strings stays on one line (the matrix reads as its
// four rows). A 1 s drive's terra,jeep,hots result file: 163 lines, 267 with nlohmann's layout
// (2026-11-26). Parse errors throw ulc::io::IoError with the file, "line L, column C" and
// nlohmann's reason.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "ulc/io/file_bytes.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::io {

using Json = nlohmann::ordered_json;

/// Parses JSON text; `file` names the source in error messages. Nesting is limited to 256
/// levels: nlohmann's parser does not recurse, but writing and comparing documents do.
inline Json parse_json(const std::string& text, const std::string& file = "<json>") {
  constexpr int kMaxDepth = 256;
  try {
    return Json::parse(text, [&file](int depth, Json::parse_event_t, Json&) {
      if (depth > kMaxDepth) throw IoError(file, "", "nesting deeper than 256 levels");
      return true;
    });
  } catch (const Json::parse_error& e) {
    // what(): "[json.exception.parse_error.101] parse error at line 1, column 14: <reason>"
    const std::string what = e.what();
    const std::string at = "parse error at ";
    const auto begin = what.find(at);
    const auto colon = begin == std::string::npos ? begin : what.find(": ", begin);
    if (colon == std::string::npos) throw IoError(file, at_byte(e.byte), what);
    throw IoError(file, what.substr(begin + at.size(), colon - begin - at.size()),
                  what.substr(colon + 2));
  } catch (const Json::exception& e) {  // out_of_range: "number overflow parsing '1e999'"
    const std::string what = e.what();
    const auto tag = what.find("] ");
    throw IoError(file, "", tag == std::string::npos ? what : what.substr(tag + 2));
  }
}

/// Reads and parses a JSON file; files over 256 MiB are refused (ours are small).
inline Json read_json_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, "", "cannot open file");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw IoError(path, "", "cannot read file size");
  if (size > (std::streamoff(256) << 20)) throw IoError(path, "", "file too large for JSON");
  in.seekg(0);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(&text[0], size)) throw IoError(path, "", "read failed");
  return parse_json(text, path);
}

namespace json_detail {

inline std::string scalar(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

inline void write(std::string& out, const Json& j, int depth) {
  const bool rows = j.is_array() && std::none_of(j.begin(), j.end(),
                                                 [](const Json& v) { return v.is_structured(); });
  if (!j.is_structured() || j.empty() || rows) {
    if (!j.is_array() || j.empty()) {
      out += scalar(j);
      return;
    }
    out += '[';
    for (std::size_t i = 0; i < j.size(); ++i) out += (i ? ", " : "") + scalar(j[i]);
    out += ']';
    return;
  }
  const std::string indent(static_cast<std::size_t>(depth) + 1, ' ');
  out += j.is_object() ? '{' : '[';
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    out += first ? "\n" : ",\n";
    first = false;
    out += indent;
    if (j.is_object()) out += scalar(Json(it.key())) + ": ";
    write(out, it.value(), depth + 1);
  }
  out += '\n' + std::string(static_cast<std::size_t>(depth), ' ') + (j.is_object() ? '}' : ']');
}

}  // namespace json_detail

/// Pretty text, one-space indent, arrays of numbers or strings on one line (see the top).
inline std::string dump_json(const Json& j) {
  std::string out;
  json_detail::write(out, j, 0);
  return out;
}

/// Writes dump_json and a newline, atomically (atomic_file.hpp); throws IoError when the file
/// cannot be written.
inline void write_json_file(const std::string& path, const Json& value) {
  write_file_text(path, dump_json(value) + "\n");
}

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

/// A finite number at `j`, else IoError naming `what`.
inline double json_to_number(const Json& j, const std::string& file, const std::string& what) {
  if (!j.is_number()) throw IoError(file, what, "expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw IoError(file, what, "the number is out of range");
  return v;
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
      if (!v.is_number() || !std::isfinite(v.get<double>()))
        throw IoError(
            file, what,
            "non-numeric entry at row " + std::to_string(r) + ", column " + std::to_string(c));
      m(r, c) = v.get<double>();
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

/// The member `key` of an object, nullptr when absent or when `j` is not an object.
inline const Json* find_member(const Json& j, const std::string& key) {
  if (!j.is_object()) return nullptr;
  const auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

}  // namespace ulc::io
