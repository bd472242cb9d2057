#include "io/ply_check.h"

#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <utility>
#include <vector>

#include "core/error.h"
#include "io/le_scalar.h"

namespace pb {

namespace {

struct Property {
  std::string name;
  int size = 0;        // bytes of a scalar (or of each list item)
  int count_size = 0;  // > 0: a list, with a count of this many bytes
  bool is_float = false;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
};

int type_size(const std::string& t, bool* is_float) {
  *is_float = t == "float" || t == "float32" || t == "double" || t == "float64";
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

// The body reader: ascii tokens or binary values in either byte order.
class Body {
 public:
  Body(const std::string& path, const std::string& field, const std::string& bytes, size_t pos, int format)
      : path_(path), field_(field), b_(bytes), pos_(pos), format_(format) {}
  // One value as a double (integers exactly up to 2^53).
  double value(int size, bool is_float) {
    if (format_ == 0) return token();
    if (size < 1 || size > 8) fail("bad value size");
    if (pos_ + static_cast<size_t>(size) > b_.size()) fail("the data ends before the declared elements do");
    unsigned char raw[8];
    std::memcpy(raw, b_.data() + pos_, static_cast<size_t>(size));
    pos_ += static_cast<size_t>(size);
    if (format_ == 2)
      for (int i = 0; i < size / 2; ++i) std::swap(raw[i], raw[size - 1 - i]);
    return decode_scalar_le(raw, size, is_float, signed_);
  }
  void set_signed(bool s) { signed_ = s; }
  [[noreturn]] void fail(const std::string& why) const { throw InputError(path_, field_, "broken PLY: " + why); }

 private:
  double token() {
    while (pos_ < b_.size() && std::isspace(static_cast<unsigned char>(b_[pos_]))) ++pos_;
    if (pos_ >= b_.size()) fail("the data ends before the declared elements do");
    const size_t start = pos_;
    while (pos_ < b_.size() && !std::isspace(static_cast<unsigned char>(b_[pos_]))) ++pos_;
    const std::string t = b_.substr(start, pos_ - start);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size()) fail("'" + t.substr(0, 20) + "' is not a number");
    return v;
  }
  const std::string& path_;
  const std::string& field_;
  const std::string& b_;
  size_t pos_;
  int format_;  // 0 ascii, 1 binary little endian, 2 binary big endian
  bool signed_ = true;
};

bool is_signed_type(const std::string& t) { return !(t.size() > 1 && t[0] == 'u'); }

// Element and property names: letters, digits, '_', '-', '.'.
bool is_name(const std::string& n) {
  if (n.empty() || n.size() > 64) return false;
  for (const char c : n)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

// What the body walk is given and keeps.
struct Walk {
  const std::string& path;
  const std::string& field;             // named in errors
  std::vector<Vec3f>* xyz = nullptr;    // when set: the vertices' x, y, z
};

[[noreturn]] void broken(const Walk& walk, const std::string& why) {
  throw InputError(walk.path, walk.field, "broken PLY: " + why);
}

// Walks the body: every declared value present; face index lists of 3 or
// more indices, each in [0, vertices). `signs`: per element, per property,
// whether its (item) type is signed.
void walk_body(const Walk& walk, const std::string& bytes, size_t body, int format,
               const std::vector<Element>& elements, const std::vector<std::vector<bool>>& signs, uint64_t vertices) {
  const auto fail = [&walk](const std::string& why) { broken(walk, why); };
  // Each declared value needs at least one byte: counts the data cannot hold
  // are rejected before anything is read or allocated.
  const uint64_t avail = bytes.size() - body;
  for (const auto& e : elements)
    if (!e.props.empty() && e.count > avail) fail("element '" + e.name + "' declares more values than the file holds");
  Body r(walk.path, walk.field, bytes, body, format);
  for (size_t ei = 0; ei < elements.size(); ++ei) {
    const Element& e = elements[ei];
    if (e.props.empty()) continue;  // holds no data, whatever its count (a loop over 10^10 would hang)
    const bool keep = walk.xyz && e.name == "vertex";
    if (keep) walk.xyz->reserve(static_cast<size_t>(e.count));
    for (uint64_t i = 0; i < e.count; ++i) {
      Vec3f xyz = Vec3f::Zero();
      for (size_t pi = 0; pi < e.props.size(); ++pi) {
        const Property& p = e.props[pi];
        const bool indices = e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index");
        if (p.count_size == 0) {
          r.set_signed(signs[ei][pi]);
          const double v = r.value(p.size, p.is_float);
          if (keep && p.name.size() == 1 && p.name[0] >= 'x' && p.name[0] <= 'z') xyz[p.name[0] - 'x'] = static_cast<float>(v);
          continue;
        }
        r.set_signed(false);
        const double n = r.value(p.count_size, false);
        if (!(n >= 0) || n != static_cast<double>(static_cast<uint64_t>(n)) || n > static_cast<double>(avail))
          fail("a list of element '" + e.name + "' has an impossible length");
        if (indices && n < 3)  // assimp's triangulation asserts (abort) on such a face: found by fuzzing
          fail("face " + std::to_string(i) + " has " + std::to_string(static_cast<int>(n)) + " vertices (3 or more)");
        r.set_signed(signs[ei][pi]);
        for (uint64_t k = 0; k < static_cast<uint64_t>(n); ++k) {
          const double v = r.value(p.size, p.is_float);
          if (indices && !(v >= 0 && v < static_cast<double>(vertices) && v == static_cast<double>(static_cast<int64_t>(v))))
            fail("face " + std::to_string(i) + " has vertex index " + std::to_string(v) + " (there are " +
                 std::to_string(vertices) + " vertices)");
        }
      }
      if (keep) walk.xyz->push_back(xyz);
    }
  }
}

}  // namespace

namespace {

// Where the header's last line "end_header" starts (*end) and the body
// after it (*body). That line is exactly "end_header" (a comment that
// merely contains the word does not end it: assimp reads on, found by
// fuzzing).
void find_end_header(const Walk& walk, const std::string& bytes, size_t* end, size_t* body) {
  *body = std::string::npos;
  *end = 0;
  for (size_t pos = 0; pos < bytes.size();) {
    size_t nl = bytes.find('\n', pos);
    if (nl == std::string::npos) nl = bytes.size();
    std::string l = bytes.substr(pos, nl - pos);
    while (!l.empty() && (l.back() == '\r' || l.back() == ' ' || l.back() == '\t')) l.pop_back();
    if (l == "end_header") {
      *end = pos;
      *body = nl + 1;
      break;
    }
    pos = nl + 1;
  }
  if (*body == std::string::npos)
    throw InputError(walk.path, walk.field, "truncated PLY: the header has no 'end_header' line");
  if (*body > bytes.size()) *body = bytes.size();
}

// The header is text lines: no control bytes, CR only before LF (assimp
// misread a property name holding NUL bytes, and a CR inside a line, and
// crashed: found by fuzzing). Bytes >= 0x80 (UTF-8 in a comment) are fine;
// names are checked as they are read.
void check_header_bytes(const Walk& walk, const std::string& bytes, size_t end) {
  for (size_t i = 0; i < end; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c < 0x20 && c != '\n' && c != '\t' && !(c == '\r' && i + 1 < bytes.size() && bytes[i + 1] == '\n'))
      broken(walk, "the header holds control byte " + std::to_string(c) + " at offset " + std::to_string(i) +
                       (c == '\r' ? " (a carriage return not ending a line)" : ""));
  }
}

struct PlyHeader {
  int format = -1;  // 0 ascii, 1 binary little endian, 2 binary big endian
  std::vector<Element> elements;
  std::vector<std::vector<bool>> signs;  // per element, per property: the (item) type is signed
};

// An "element name count" line (w past the key).
void add_element(const Walk& walk, const std::string& line, std::istringstream& w, PlyHeader& h) {
  Element e;
  std::string count;
  if (!(w >> e.name >> count) || count.empty() || count.find_first_not_of("0123456789") != std::string::npos ||
      count.size() > 10)
    broken(walk, "bad element line '" + line.substr(0, 60) + "'");
  e.count = std::strtoull(count.c_str(), nullptr, 10);
  if (!is_name(e.name)) broken(walk, "bad element name in '" + line.substr(0, 60) + "'");
  for (const auto& o : h.elements)
    if (o.name == e.name) broken(walk, "element '" + e.name + "' is declared twice");
  h.elements.push_back(e);
  h.signs.emplace_back();
}

// A "property [list count_type] type name" line of the last element (w
// past the key).
void add_property(const Walk& walk, const std::string& line, std::istringstream& w, PlyHeader& h) {
  if (h.elements.empty()) broken(walk, "a property before any element");
  std::string type;
  w >> type;
  Property p;
  std::string item = type;
  bool f = false;
  if (type == "list") {
    std::string ct;
    w >> ct >> item;
    p.count_size = type_size(ct, &f);
    if (p.count_size == 0 || f) broken(walk, "bad list count type in '" + line.substr(0, 60) + "'");
  }
  p.size = type_size(item, &p.is_float);
  std::string rest;
  if (p.size == 0 || !(w >> p.name) || !is_name(p.name) || (w >> rest))
    broken(walk, "bad property line '" + line.substr(0, 60) + "'");
  for (const auto& o : h.elements.back().props)
    if (o.name == p.name)
      broken(walk, "property '" + p.name + "' of element '" + h.elements.back().name + "' is declared twice");
  h.elements.back().props.push_back(p);
  h.signs.back().push_back(is_signed_type(item));
}

// The header's lines after "ply": the format, the elements and their properties.
PlyHeader parse_header(const Walk& walk, const std::string& text) {
  std::istringstream header(text);
  std::string line;
  PlyHeader h;
  std::getline(header, line);  // "ply"
  while (std::getline(header, line)) {
    std::istringstream w(line);
    std::string key;
    if (!(w >> key)) continue;
    if (h.format < 0 && key != "format")
      broken(walk, "the line after 'ply' must be the format line (assimp needs it there)");
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (h.format >= 0) broken(walk, "two format lines");
      std::string f;
      w >> f;
      h.format = f == "ascii" ? 0 : f == "binary_little_endian" ? 1 : f == "binary_big_endian" ? 2 : -1;
      if (h.format < 0) broken(walk, "unknown format '" + f + "'");
    } else if (key == "element") {
      add_element(walk, line, w, h);
    } else if (key == "property") {
      add_property(walk, line, w, h);
    } else {
      broken(walk, "unknown header line '" + line.substr(0, 60) + "'");
    }
  }
  if (h.format < 0) broken(walk, "no format line");
  return h;
}

// The number of vertices: a mesh needs a vertex element with scalar x, y and z.
uint64_t vertex_count(const Walk& walk, const std::vector<Element>& elements) {
  const Element* vertex = nullptr;
  for (const auto& e : elements)
    if (e.name == "vertex") vertex = &e;
  if (vertex == nullptr) broken(walk, "no 'vertex' element");
  for (const char* axis : {"x", "y", "z"}) {
    bool found = false;
    for (const auto& p : vertex->props) found = found || (p.name == axis && p.count_size == 0);
    if (!found) broken(walk, std::string("the vertex element has no scalar property '") + axis + "'");
  }
  return vertex->count;
}

// The checked header; *body: where the body starts.
PlyHeader read_header(const Walk& walk, const std::string& bytes, size_t* body) {
  if (!(bytes.compare(0, 4, "ply\n") == 0 || bytes.compare(0, 5, "ply\r\n") == 0))
    throw InputError(walk.path, walk.field, "not a PLY file (the first line is not 'ply')");
  size_t end = 0;
  find_end_header(walk, bytes, &end, body);
  check_header_bytes(walk, bytes, end);
  return parse_header(walk, bytes.substr(0, end));
}

void read_ply(const Walk& walk, const std::string& bytes) {
  size_t body = 0;
  const PlyHeader h = read_header(walk, bytes, &body);
  const uint64_t vertices = vertex_count(walk, h.elements);
  walk_body(walk, bytes, body, h.format, h.elements, h.signs, vertices);
}

}  // namespace

void check_ply(const std::string& path, const std::string& bytes) { read_ply(Walk{path, "mesh"}, bytes); }

std::vector<Vec3f> read_ply_vertices(const std::string& path, const std::string& bytes, const std::string& field) {
  std::vector<Vec3f> xyz;
  read_ply(Walk{path, field, &xyz}, bytes);
  return xyz;
}

std::map<std::string, uint64_t> ply_element_counts(const std::string& path, const std::string& bytes,
                                                   const std::string& field) {
  size_t body = 0;
  std::map<std::string, uint64_t> out;
  for (const Element& e : read_header(Walk{path, field}, bytes, &body).elements) out[e.name] = e.count;
  return out;
}

}  // namespace pb
