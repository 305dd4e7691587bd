// A small JSON value, parser and writer for ULC's own files (ground_truth.json, result files).
// Objects keep their keys in insertion order so written files are stable and diffable. Numbers
// are doubles written with 17 significant digits, so a double survives a round trip exactly.
// Parse errors throw ulc::io::IoError with the file, "line L, column C" and the reason.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "ulc/io/io_error.hpp"

namespace ulc::io {

class Json {
 public:
  using Array = std::vector<Json>;
  using Object = std::vector<std::pair<std::string, Json>>;

  Json() = default;  // null
  Json(std::nullptr_t) {}
  Json(bool b) : type_(Type::kBool), bool_(b) {}
  Json(double d) : type_(Type::kNumber), number_(d) {}
  Json(int i) : Json(static_cast<double>(i)) {}
  Json(long i) : Json(static_cast<double>(i)) {}
  Json(long long i) : Json(static_cast<double>(i)) {}
  Json(unsigned i) : Json(static_cast<double>(i)) {}
  Json(unsigned long i) : Json(static_cast<double>(i)) {}
  Json(unsigned long long i) : Json(static_cast<double>(i)) {}
  Json(const char* s) : Json(std::string(s)) {}
  Json(std::string s) : type_(Type::kString), string_(std::move(s)) {}
  Json(Array a) : type_(Type::kArray), array_(std::move(a)) {}
  Json(Object o) : type_(Type::kObject), object_(std::move(o)) {}

  static Json array() { return Json(Array{}); }
  static Json object() { return Json(Object{}); }

  bool is_null() const { return type_ == Type::kNull; }
  bool is_bool() const { return type_ == Type::kBool; }
  bool is_number() const { return type_ == Type::kNumber; }
  bool is_string() const { return type_ == Type::kString; }
  bool is_array() const { return type_ == Type::kArray; }
  bool is_object() const { return type_ == Type::kObject; }

  bool as_bool() const { return expect(Type::kBool, "a boolean"), bool_; }
  double as_number() const { return expect(Type::kNumber, "a number"), number_; }
  const std::string& as_string() const { return expect(Type::kString, "a string"), string_; }
  const Array& as_array() const { return expect(Type::kArray, "an array"), array_; }
  const Object& as_object() const { return expect(Type::kObject, "an object"), object_; }
  Array& as_array() { return expect(Type::kArray, "an array"), array_; }
  Object& as_object() { return expect(Type::kObject, "an object"), object_; }

  /// Object member lookup; nullptr when absent or when this is not an object.
  const Json* find(const std::string& key) const {
    if (!is_object()) return nullptr;
    for (const auto& kv : object_)
      if (kv.first == key) return &kv.second;
    return nullptr;
  }
  /// Object member lookup that throws a type error naming the key when absent.
  const Json& at(const std::string& key) const {
    const Json* j = find(key);
    if (!j) throw std::runtime_error("missing key \"" + key + "\"");
    return *j;
  }
  /// Inserts or replaces a member; turns null into an object.
  Json& operator[](const std::string& key) {
    if (is_null()) type_ = Type::kObject;
    auto& obj = as_object();
    for (auto& kv : obj)
      if (kv.first == key) return kv.second;
    obj.emplace_back(key, Json());
    return obj.back().second;
  }
  void push_back(Json v) {
    if (is_null()) type_ = Type::kArray;
    as_array().push_back(std::move(v));
  }
  std::size_t size() const {
    if (is_array()) return array_.size();
    if (is_object()) return object_.size();
    return 0;
  }
  const Json& operator[](std::size_t i) const { return as_array().at(i); }

  /// Serialises; indent < 0 gives one line, otherwise pretty-printed with that indent.
  std::string dump(int indent = 1) const {
    std::string out;
    write(out, indent, 0);
    return out;
  }

 private:
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };

  void expect(Type t, const char* what) const {
    if (type_ != t) throw std::runtime_error(std::string("JSON value is not ") + what);
  }

  static void write_string(std::string& out, const std::string& s) {
    out += '"';
    for (unsigned char c : s) {
      switch (c) {
        case '"':
          out += "\\\"";
          break;
        case '\\':
          out += "\\\\";
          break;
        case '\n':
          out += "\\n";
          break;
        case '\t':
          out += "\\t";
          break;
        case '\r':
          out += "\\r";
          break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
          } else {
            out += static_cast<char>(c);
          }
      }
    }
    out += '"';
  }

  static void write_number(std::string& out, double d) {
    if (!std::isfinite(d)) {  // JSON has no NaN/Inf: write null so readers see "unknown"
      out += "null";
      return;
    }
    if (d == std::floor(d) && std::fabs(d) < 1e15) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.0f", d);
      out += buf;
      return;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", d);
    out += buf;
  }

  void write(std::string& out, int indent, int depth) const {
    const bool pretty = indent >= 0;
    auto newline = [&](int d) {
      if (!pretty) return;
      out += '\n';
      out.append(static_cast<std::size_t>(d * indent), ' ');
    };
    if (is_null())
      out += "null";
    else if (is_bool())
      out += bool_ ? "true" : "false";
    else if (is_number())
      write_number(out, number_);
    else if (is_string())
      write_string(out, string_);
    else if (is_array()) {
      const auto& a = array_;
      // Arrays of numbers (matrix rows, vectors) stay on one line: they read as rows.
      bool flat = true;
      for (const auto& v : a) flat = flat && v.is_number();
      out += '[';
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (i) out += flat && pretty ? ", " : ",";
        if (!flat) newline(depth + 1);
        a[i].write(out, indent, depth + 1);
      }
      if (!flat && !a.empty()) newline(depth);
      out += ']';
    } else {
      const auto& o = object_;
      out += '{';
      for (std::size_t i = 0; i < o.size(); ++i) {
        if (i) out += ',';
        newline(depth + 1);
        write_string(out, o[i].first);
        out += pretty ? ": " : ":";
        o[i].second.write(out, indent, depth + 1);
      }
      if (!o.empty()) newline(depth);
      out += '}';
    }
  }

  // A tagged record rather than std::variant: GCC 12 raises false maybe-uninitialized
  // warnings on variants of strings and vectors, and our targets build with -Werror.
  Type type_ = Type::kNull;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  Array array_;
  Object object_;
};

namespace detail {

/// Recursive-descent parser with a depth limit (no stack exhaustion on hostile input).
class JsonParser {
 public:
  JsonParser(const std::string& text, std::string file) : s_(text), file_(std::move(file)) {}

  Json parse_document() {
    skip_ws();
    if (i_ >= s_.size()) fail("empty document");
    Json v = parse_value(0);
    skip_ws();
    if (i_ != s_.size()) fail("unexpected text after the JSON value");
    return v;
  }

 private:
  static constexpr int kMaxDepth = 256;

  [[noreturn]] void fail(const std::string& reason) const {
    std::size_t line = 1, col = 1;
    for (std::size_t k = 0; k < i_ && k < s_.size(); ++k) {
      if (s_[k] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw IoError(file_, "line " + std::to_string(line) + ", column " + std::to_string(col),
                  reason);
  }

  void skip_ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\n' || s_[i_] == '\t' || s_[i_] == '\r'))
      ++i_;
  }

  bool consume(const char* word) {
    std::size_t n = std::char_traits<char>::length(word);
    if (s_.compare(i_, n, word) != 0) return false;
    i_ += n;
    return true;
  }

  Json parse_value(int depth) {
    if (depth > kMaxDepth) fail("nesting deeper than 256 levels");
    skip_ws();
    if (i_ >= s_.size()) fail("unexpected end of file");
    const char c = s_[i_];
    if (c == '{') return parse_object(depth);
    if (c == '[') return parse_array(depth);
    if (c == '"') return Json(parse_string());
    if (consume("true")) return Json(true);
    if (consume("false")) return Json(false);
    if (consume("null")) return Json();
    if (c == '-' || (c >= '0' && c <= '9')) return Json(parse_number());
    fail(std::string("unexpected character '") + c + "'");
  }

  Json parse_object(int depth) {
    ++i_;  // {
    Json::Object obj;
    skip_ws();
    if (i_ < s_.size() && s_[i_] == '}') {
      ++i_;
      return Json(std::move(obj));
    }
    for (;;) {
      skip_ws();
      if (i_ >= s_.size() || s_[i_] != '"') fail("expected a string key");
      std::string key = parse_string();
      skip_ws();
      if (i_ >= s_.size() || s_[i_] != ':') fail("expected ':' after a key");
      ++i_;
      obj.emplace_back(std::move(key), parse_value(depth + 1));
      skip_ws();
      if (i_ < s_.size() && s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (i_ < s_.size() && s_[i_] == '}') {
        ++i_;
        return Json(std::move(obj));
      }
      fail("expected ',' or '}' in an object");
    }
  }

  Json parse_array(int depth) {
    ++i_;  // [
    Json::Array arr;
    skip_ws();
    if (i_ < s_.size() && s_[i_] == ']') {
      ++i_;
      return Json(std::move(arr));
    }
    for (;;) {
      arr.push_back(parse_value(depth + 1));
      skip_ws();
      if (i_ < s_.size() && s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (i_ < s_.size() && s_[i_] == ']') {
        ++i_;
        return Json(std::move(arr));
      }
      fail("expected ',' or ']' in an array");
    }
  }

  static void append_utf8(std::string& out, std::uint32_t cp) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  std::uint32_t parse_hex4() {
    if (i_ + 4 > s_.size()) fail("truncated \\u escape");
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) {
      const char h = s_[i_++];
      v <<= 4;
      if (h >= '0' && h <= '9')
        v |= static_cast<std::uint32_t>(h - '0');
      else if (h >= 'a' && h <= 'f')
        v |= static_cast<std::uint32_t>(h - 'a' + 10);
      else if (h >= 'A' && h <= 'F')
        v |= static_cast<std::uint32_t>(h - 'A' + 10);
      else
        fail("bad hex digit in \\u escape");
    }
    return v;
  }

  std::string parse_string() {
    ++i_;  // "
    std::string out;
    while (i_ < s_.size()) {
      const char c = s_[i_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) fail("control character inside a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (i_ >= s_.size()) break;
      const char e = s_[i_++];
      switch (e) {
        case '"':
          out += '"';
          break;
        case '\\':
          out += '\\';
          break;
        case '/':
          out += '/';
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u': {
          std::uint32_t cp = parse_hex4();
          if (cp >= 0xD800 && cp < 0xDC00 && consume("\\u")) {
            const std::uint32_t lo = parse_hex4();
            if (lo < 0xDC00 || lo > 0xDFFF) fail("bad UTF-16 surrogate pair");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
          }
          append_utf8(out, cp);
          break;
        }
        default:
          fail(std::string("unknown escape '\\") + e + "'");
      }
    }
    fail("unterminated string");
  }

  double parse_number() {
    const std::size_t start = i_;
    if (s_[i_] == '-') ++i_;
    auto digits = [&] {
      const std::size_t d0 = i_;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
      return i_ > d0;
    };
    if (!digits()) fail("malformed number");
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      if (!digits()) fail("malformed number");
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      if (!digits()) fail("malformed number");
    }
    std::istringstream in(s_.substr(start, i_ - start));
    in.imbue(std::locale::classic());
    double v = 0;
    in >> v;
    if (in.fail()) fail("number out of range");
    return v;
  }

  const std::string& s_;
  std::string file_;
  std::size_t i_ = 0;
};

}  // namespace detail

/// Parses JSON text; `file` only names the source in error messages.
inline Json parse_json(const std::string& text, const std::string& file = "<json>") {
  return detail::JsonParser(text, file).parse_document();
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

/// Writes JSON (pretty, trailing newline); throws IoError when the file cannot be written.
inline void write_json_file(const std::string& path, const Json& value) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(path, "", "cannot open file for writing");
  const std::string text = value.dump(1) + "\n";
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (!out) throw IoError(path, "", "write failed");
}

}  // namespace ulc::io
