#include "io/cloud.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "io/le_scalar.h"
#include "io/ply_check.h"
#include "io/validate.h"

namespace pb {

namespace {

constexpr uint64_t kMaxPoints = 100'000'000;  // 1.2 GB of points: larger is a broken header, not a scene

struct PcdField {
  std::string name;
  int size = 4;      // bytes per value
  char type = 'F';   // F float, I signed, U unsigned
  int count = 1;     // values per point
  size_t offset = 0; // bytes before it in a binary point record
};

struct PcdHeader {
  std::vector<PcdField> fields;
  uint64_t width = 0, height = 1, points = 0;
  double viewpoint[7] = {0, 0, 0, 1, 0, 0, 0};  // tx ty tz qw qx qy qz
  std::string data;                              // ascii | binary | binary_compressed
  size_t body = 0;                               // first byte after the DATA line
  size_t record = 0;                             // bytes of one binary point record
};

[[noreturn]] void fail(const std::string& path, const std::string& field, const std::string& why) {
  throw InputError(path, field, why);
}

uint64_t parse_count(const std::string& path, const std::string& key, const std::string& tok) {
  if (tok.empty() || tok.size() > 12 || tok.find_first_not_of("0123456789") != std::string::npos)
    fail(path, key, "'" + tok.substr(0, 20) + "' is not a non-negative integer");
  return std::strtoull(tok.c_str(), nullptr, 10);
}

// The per-field lists of a header (SIZE, TYPE, COUNT), as given, and
// whether it had a POINTS line.
struct FieldLists {
  std::vector<std::string> sizes, types, counts;
  bool have_points = false;
};

// The header line starting at `pos` (at most 4096 bytes of it); pos moves
// past its newline.
std::string next_header_line(const std::string& path, const std::string& bytes, size_t& pos) {
  if (pos >= bytes.size()) fail(path, "DATA", "the header ends without a DATA line");
  size_t nl = bytes.find('\n', pos);
  if (nl == std::string::npos) nl = bytes.size();
  std::string line = bytes.substr(pos, std::min<size_t>(nl - pos, 4096));
  pos = nl + 1;
  for (char c : line)
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r')
      fail(path, "header", "a header line holds control byte " + std::to_string(static_cast<int>(c)));
  return line;
}

// One header line `key vals...` into h (or the field lists).
void apply_header_line(const std::string& path, const std::string& line, const std::string& key,
                       const std::vector<std::string>& vals, PcdHeader& h, FieldLists& lists) {
  if (key == "VERSION") return;
  if (key == "FIELDS") {
    if (vals.empty() || vals.size() > 1000) fail(path, "FIELDS", "expected 1 to 1000 field names");
    for (const auto& v : vals) h.fields.push_back(PcdField{v});
  } else if (key == "SIZE") {
    lists.sizes = vals;
  } else if (key == "TYPE") {
    lists.types = vals;
  } else if (key == "COUNT") {
    lists.counts = vals;
  } else if (key == "WIDTH" && vals.size() == 1) {
    h.width = parse_count(path, key, vals[0]);
  } else if (key == "HEIGHT" && vals.size() == 1) {
    h.height = parse_count(path, key, vals[0]);
  } else if (key == "POINTS" && vals.size() == 1) {
    h.points = parse_count(path, key, vals[0]);
    lists.have_points = true;
  } else if (key == "VIEWPOINT" && vals.size() == 7) {
    for (int i = 0; i < 7; ++i) {
      char* end = nullptr;
      h.viewpoint[i] = std::strtod(vals[i].c_str(), &end);
      if (*end != '\0' || !std::isfinite(h.viewpoint[i])) fail(path, "VIEWPOINT", "expected 7 finite numbers");
    }
  } else if (key == "DATA" && vals.size() == 1) {
    h.data = vals[0];
    if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed")
      fail(path, "DATA", "'" + h.data.substr(0, 20) + "' is not ascii, binary or binary_compressed");
  } else {
    fail(path, key.substr(0, 20), "unknown or malformed header line '" + line.substr(0, 60) + "'");
  }
}

// Each field's size, type, count and offset in the record (and the
// record's size), checked.
void lay_out_fields(const std::string& path, const FieldLists& lists, PcdHeader& h) {
  const size_t nf = h.fields.size();
  if (nf == 0) fail(path, "FIELDS", "missing");
  if (lists.sizes.size() != nf) fail(path, "SIZE", "expected one size per field (" + std::to_string(nf) + ")");
  if (lists.types.size() != nf) fail(path, "TYPE", "expected one type per field (" + std::to_string(nf) + ")");
  if (!lists.counts.empty() && lists.counts.size() != nf) fail(path, "COUNT", "expected one count per field");
  for (size_t i = 0; i < nf; ++i) {
    PcdField& f = h.fields[i];
    const std::string& size = lists.sizes[i];
    const std::string& type = lists.types[i];
    f.size = size == "1" ? 1 : size == "2" ? 2 : size == "4" ? 4 : size == "8" ? 8 : 0;
    if (f.size == 0) fail(path, "SIZE", "field '" + f.name + "': size must be 1, 2, 4 or 8");
    if (type.size() != 1 || std::string("FIU").find(type[0]) == std::string::npos)
      fail(path, "TYPE", "field '" + f.name + "': type must be F, I or U");
    f.type = type[0];
    if (f.type == 'F' && f.size != 4 && f.size != 8) fail(path, "SIZE", "field '" + f.name + "': F needs size 4 or 8");
    f.count = lists.counts.empty()
                  ? 1
                  : static_cast<int>(std::min<uint64_t>(parse_count(path, "COUNT", lists.counts[i]), 1u << 20));
    if (f.count < 1) fail(path, "COUNT", "field '" + f.name + "': count must be >= 1");
    f.offset = h.record;
    h.record += static_cast<size_t>(f.size) * static_cast<size_t>(f.count);
  }
}

// The header's lines up to and including DATA.
PcdHeader parse_pcd_header(const std::string& path, const std::string& bytes) {
  PcdHeader h;
  FieldLists lists;
  size_t pos = 0;
  while (h.data.empty()) {
    const std::string line = next_header_line(path, bytes, pos);
    std::istringstream w(line);
    std::string key;
    if (!(w >> key) || key[0] == '#') continue;
    std::vector<std::string> vals;
    for (std::string t; w >> t;) vals.push_back(t);
    apply_header_line(path, line, key, vals, h, lists);
  }
  h.body = std::min(pos, bytes.size());
  lay_out_fields(path, lists, h);
  if (h.width == 0 || h.height == 0) fail(path, "WIDTH", "WIDTH and HEIGHT must be positive");
  if (h.width > kMaxPoints || h.height > kMaxPoints || h.width * h.height > kMaxPoints)
    fail(path, "WIDTH", "more than " + std::to_string(kMaxPoints) + " points");
  if (lists.have_points && h.points != h.width * h.height)
    fail(path, "POINTS", std::to_string(h.points) + " points but WIDTH x HEIGHT = " + std::to_string(h.width * h.height));
  h.points = h.width * h.height;
  for (const char* axis : {"x", "y", "z"}) {
    bool found = false;
    for (const auto& f : h.fields) found = found || (f.name == axis && f.count == 1);
    if (!found) fail(path, "FIELDS", std::string("no field '") + axis + "' (one value per point)");
  }
  return h;
}

double binary_value(const unsigned char* p, const PcdField& f) {
  // Little endian, as PCL writes on every platform it runs on.
  return decode_scalar_le(p, f.size, f.type == 'F', f.type == 'I');
}

// LZF (the compression of PCL's binary_compressed): control byte c < 32 is a
// literal run of c + 1 bytes; otherwise a back reference of length
// (c >> 5) + 2 (7: one more length byte follows) at distance
// ((c & 31) << 8) + next byte + 1. False unless it produces exactly out_len bytes.
bool lzf_decompress(const unsigned char* in, size_t in_len, unsigned char* out, size_t out_len) {
  size_t ip = 0, op = 0;
  while (ip < in_len) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {
      const size_t n = ctrl + 1;
      if (ip + n > in_len || op + n > out_len) return false;
      std::memcpy(out + op, in + ip, n);
      ip += n;
      op += n;
      continue;
    }
    size_t len = ctrl >> 5;
    if (len == 7) {
      if (ip >= in_len) return false;
      len += in[ip++];
    }
    len += 2;
    if (ip >= in_len) return false;
    const size_t back = ((ctrl & 31u) << 8) + in[ip++] + 1;
    if (back > op || op + len > out_len) return false;
    for (size_t k = 0; k < len; ++k, ++op) out[op] = out[op - back];  // may overlap: byte by byte
  }
  return op == out_len;
}

// The raw coordinates (file units, file frame) of every point.
std::vector<Vec3> pcd_points(const std::string& path, const std::string& bytes, const PcdHeader& h) {
  int ix[3] = {-1, -1, -1};
  for (size_t i = 0; i < h.fields.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (h.fields[i].name == std::string(1, static_cast<char>('x' + a)) && ix[a] < 0) ix[a] = static_cast<int>(i);
  const uint64_t n = h.points;
  const size_t avail = bytes.size() - h.body;
  std::vector<Vec3> pts;
  if (h.data == "ascii") {
    size_t values = 0;
    for (const auto& f : h.fields) values += static_cast<size_t>(f.count);
    if (n > (avail + 1) / (2 * values)) fail(path, "POINTS", "the data holds fewer points than declared");
    pts.reserve(static_cast<size_t>(n));
    std::istringstream in(bytes.substr(h.body));
    std::string line;
    uint64_t line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      std::istringstream w(line);
      std::vector<std::string> tok;
      for (std::string t; w >> t;) tok.push_back(t);
      if (tok.empty()) continue;
      const std::string where = "point " + std::to_string(pts.size());
      if (pts.size() == n) fail(path, where, "more points than POINTS declares");
      if (tok.size() != values)
        fail(path, where, std::to_string(tok.size()) + " values, the header declares " + std::to_string(values));
      Vec3 p;
      for (int a = 0; a < 3; ++a) {
        size_t k = 0;
        for (int i = 0; i < ix[a]; ++i) k += static_cast<size_t>(h.fields[i].count);
        char* end = nullptr;
        p[a] = std::strtod(tok[k].c_str(), &end);
        if (*end != '\0') fail(path, where, "'" + tok[k].substr(0, 20) + "' is not a number");
      }
      pts.push_back(p);
    }
    if (pts.size() != n) fail(path, "POINTS", std::to_string(n) + " declared, " + std::to_string(pts.size()) + " in the data");
    return pts;
  }
  const size_t total = static_cast<size_t>(n) * h.record;
  if (h.record > 0 && static_cast<size_t>(n) > std::numeric_limits<size_t>::max() / h.record)
    fail(path, "POINTS", "too large");
  std::string unpacked;
  const unsigned char* data = nullptr;
  if (h.data == "binary") {
    if (avail < total) fail(path, "DATA", "binary data of " + std::to_string(avail) + " bytes, the header needs " + std::to_string(total));
    data = reinterpret_cast<const unsigned char*>(bytes.data() + h.body);
  } else {
    if (avail < 8) fail(path, "DATA", "binary_compressed data without its sizes");
    uint32_t csize = 0, usize = 0;
    std::memcpy(&csize, bytes.data() + h.body, 4);
    std::memcpy(&usize, bytes.data() + h.body + 4, 4);
    if (usize != total) fail(path, "DATA", "uncompressed size " + std::to_string(usize) + ", the header needs " + std::to_string(total));
    // LZF expands at most 264 bytes out of 3: a larger claim is a broken file
    // (checked before the buffer is allocated).
    if (total / 88 > csize + 1) fail(path, "DATA", "compressed size " + std::to_string(csize) + " too small for " + std::to_string(total) + " bytes");
    if (csize > avail - 8) fail(path, "DATA", "compressed size " + std::to_string(csize) + " beyond the end of the file");
    unpacked.resize(total);
    if (!lzf_decompress(reinterpret_cast<const unsigned char*>(bytes.data() + h.body + 8), csize,
                        reinterpret_cast<unsigned char*>(unpacked.data()), total))
      fail(path, "DATA", "corrupt compressed data");
    data = reinterpret_cast<const unsigned char*>(unpacked.data());
  }
  pts.resize(static_cast<size_t>(n));
  for (int a = 0; a < 3; ++a) {
    const PcdField& f = h.fields[ix[a]];
    for (size_t i = 0; i < pts.size(); ++i) {
      // binary: one record per point; compressed: one block per field.
      const size_t at = h.data == "binary" ? i * h.record + f.offset : f.offset * static_cast<size_t>(n) + i * f.size;
      pts[i][a] = binary_value(data + at, f);
    }
  }
  return pts;
}

std::string lower_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot + 1);
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

}  // namespace

CloudUnits parse_cloud_units(const std::string& text, const std::string& field) {
  if (text == "auto") return CloudUnits::automatic;
  if (text == "mm") return CloudUnits::millimetres;
  if (text == "m") return CloudUnits::metres;
  throw InputError("", field, "'" + text + "' is not auto, mm or m");
}

PointCloudFile parse_cloud(const std::string& path, const std::string& bytes, CloudUnits units) {
  const std::string ext = lower_extension(path);
  PointCloudFile out;
  std::vector<Vec3> raw;
  if (ext == "pcd") {
    const PcdHeader h = parse_pcd_header(path, bytes);
    raw = pcd_points(path, bytes, h);
    out.width = static_cast<int>(h.width);
    out.height = static_cast<int>(h.height);
    const double* vp = h.viewpoint;
    Eigen::Quaterniond q(vp[3], vp[4], vp[5], vp[6]);
    if (!(q.norm() > 1e-12)) fail(path, "VIEWPOINT", "the orientation quaternion is zero");
    const Mat3 R = q.normalized().toRotationMatrix();
    const Vec3 t(vp[0], vp[1], vp[2]);
    if (!R.isIdentity(1e-12) || !t.isZero(0))
      for (Vec3& p : raw) p = R.transpose() * (p - t);  // into the sensor's frame
  } else if (ext == "ply") {
    for (const Vec3f& v : read_ply_vertices(path, bytes, "cloud")) raw.push_back(v.cast<double>());
    out.width = static_cast<int>(raw.size());
    out.height = 1;
  } else {
    fail(path, "cloud", "not a .pcd or .ply file");
  }
  std::vector<double> zs;
  for (const Vec3& p : raw)
    if (p.allFinite()) zs.push_back(std::abs(p.z()));
  if (zs.empty()) fail(path, "points", "no point with finite coordinates");
  std::nth_element(zs.begin(), zs.begin() + static_cast<long>(zs.size() / 2), zs.end());
  out.metres = units == CloudUnits::metres || (units == CloudUnits::automatic && zs[zs.size() / 2] < 20.0);
  const double k = out.metres ? 1000.0 : 1.0;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  out.points.reserve(raw.size());
  for (const Vec3& p : raw) {
    const Vec3 s = p * k;
    const Vec3f f = s.cast<float>();
    out.points.push_back(f.allFinite() ? f : Vec3f(nan, nan, nan));
  }
  return out;
}

PointCloudFile read_cloud(const std::string& path, CloudUnits units) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cloud", "cannot open the point cloud file");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) throw InputError(path, "cloud", "the file is empty");
  return parse_cloud(path, bytes, units);
}

}  // namespace pb
