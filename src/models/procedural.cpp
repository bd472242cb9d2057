// The project's own models, built in code from three closed primitives:
// boxes, prisms (a star-shaped polygon extruded along x) and surfaces of
// revolution (a profile r(z) from the bottom pole to the top pole revolved
// about z). Each primitive is a closed, consistently oriented triangle mesh
// (every edge used once in each direction, normals outward); models made of
// several primitives keep them as separate closed parts that touch or
// interpenetrate, which renders as their union. Units mm, up = +z, origin at
// the bounding box centre (finish()).
#include "models/procedural.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/error.h"

namespace pb {

namespace {

using V2 = Eigen::Vector2d;  // (r, z) of a profile or (y, z) of a polygon

void quad(Mesh* m, int a, int b, int c, int d) {
  m->faces.emplace_back(a, b, c);
  m->faces.emplace_back(a, c, d);
}

int add_vertex(Mesh* m, double x, double y, double z) {
  m->vertices.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  return static_cast<int>(m->vertices.size()) - 1;
}

// Axis-aligned box between two corners.
Mesh box_between(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    add_vertex(&m, (i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  // Quads counter-clockwise seen from outside.
  quad(&m, 0, 2, 3, 1);  // -z
  quad(&m, 4, 5, 7, 6);  // +z
  quad(&m, 0, 1, 5, 4);  // -y
  quad(&m, 2, 6, 7, 3);  // +y
  quad(&m, 0, 4, 6, 2);  // -x
  quad(&m, 1, 3, 7, 5);  // +x
  return m;
}

// Surface of revolution about +z. profile[0] and profile.back() lie on the
// axis (r = 0); the points between have r > 0 and run from the bottom pole
// round the outside to the top pole (counter-clockwise in the (r, z)
// half-plane), which makes the normals point outward.
Mesh revolve(const std::vector<V2>& profile, int segments) {
  Mesh m;
  const int n = static_cast<int>(profile.size());
  const int bottom = add_vertex(&m, 0, 0, profile.front().y());
  std::vector<int> ring_start;
  for (int i = 1; i < n - 1; ++i) {
    ring_start.push_back(static_cast<int>(m.vertices.size()));
    for (int j = 0; j < segments; ++j) {
      const double a = 2.0 * M_PI * j / segments;
      add_vertex(&m, profile[i].x() * std::cos(a), profile[i].x() * std::sin(a), profile[i].y());
    }
  }
  const int top = add_vertex(&m, 0, 0, profile.back().y());
  const int rings = static_cast<int>(ring_start.size());
  for (int j = 0; j < segments; ++j) {
    const int j1 = (j + 1) % segments;
    m.faces.emplace_back(bottom, ring_start[0] + j1, ring_start[0] + j);
    for (int r = 0; r + 1 < rings; ++r)
      quad(&m, ring_start[r] + j, ring_start[r] + j1, ring_start[r + 1] + j1, ring_start[r + 1] + j);
    m.faces.emplace_back(ring_start[rings - 1] + j, ring_start[rings - 1] + j1, top);
  }
  return m;
}

// Prism: a polygon in the (y, z) plane, counter-clockwise with y right and
// z up, star-shaped about `centre`, extruded over x in [-length/2, length/2].
Mesh extrude_x(const std::vector<V2>& poly, const V2& centre, double length) {
  Mesh m;
  const int n = static_cast<int>(poly.size());
  const double x0 = -0.5 * length, x1 = 0.5 * length;
  const int back_c = add_vertex(&m, x0, centre.x(), centre.y());
  const int front_c = add_vertex(&m, x1, centre.x(), centre.y());
  const int back = static_cast<int>(m.vertices.size());
  for (const auto& p : poly) add_vertex(&m, x0, p.x(), p.y());
  const int front = static_cast<int>(m.vertices.size());
  for (const auto& p : poly) add_vertex(&m, x1, p.x(), p.y());
  for (int k = 0; k < n; ++k) {
    const int k1 = (k + 1) % n;
    m.faces.emplace_back(front_c, front + k, front + k1);  // +x cap
    m.faces.emplace_back(back_c, back + k1, back + k);     // -x cap
    quad(&m, back + k, back + k1, front + k1, front + k);   // side, outward
  }
  return m;
}

// Origin at the bounding box centre; vertex normals.
Mesh finish(Mesh m) {
  const Eigen::AlignedBox3f b = m.bounds();
  Pose T;
  T.t = -b.center().cast<double>();
  m.transform(T);
  m.compute_vertex_normals();
  return m;
}

std::vector<double> parse_dims(const std::string& kind, const std::string& args, size_t count) {
  std::vector<double> v;
  std::stringstream ss(args);
  std::string item;
  while (std::getline(ss, item, 'x')) {
    char* end = nullptr;
    const double d = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !(d > 0) || !std::isfinite(d))
      throw InputError("", "source",
                       "generated model '" + kind + "': '" + args + "' must be " + std::to_string(count) +
                           " positive sizes in mm separated by 'x'");
    v.push_back(d);
  }
  if (v.size() != count)
    throw InputError("", "source",
                     "generated model '" + kind + "': '" + args + "' must be " + std::to_string(count) +
                         " positive sizes in mm separated by 'x'");
  return v;
}

}  // namespace

Mesh make_box(double sx, double sy, double sz) {
  return finish(box_between(Vec3(-sx / 2, -sy / 2, -sz / 2), Vec3(sx / 2, sy / 2, sz / 2)));
}

Mesh make_cylinder(double radius, double height, int segments) {
  return finish(revolve({{0, 0}, {radius, 0}, {radius, height}, {0, height}}, segments));
}

// 1 litre gable-top carton (Tetra-Rex-like): a 70 x 70 mm body 195 mm high,
// a gable roof rising 33 mm at 45 degrees on both sides of a ridge along x,
// and a sealed top fin 4 mm thick along the ridge, 12 mm above the roof
// line. Total 70 x 70 x 240 mm. Symmetric under a half turn about z.
Mesh make_milk_carton() {
  const double w = 70.0, body = 195.0, fin_half = 2.0, fin_top = 240.0;
  const double h = w / 2;                        // roof at 45 degrees
  const double fin_base = body + (h - fin_half);  // roof height at |y| = fin_half
  const std::vector<V2> poly = {{-h, 0},          {h, 0},
                                {h, body},        {fin_half, fin_base},
                                {fin_half, fin_top}, {-fin_half, fin_top},
                                {-fin_half, fin_base}, {-h, body}};
  return finish(extrude_x(poly, V2(0, body / 2), w));
}

// LS5-like lidar unit (the thesis's Optronic LS5 is not public; this is a
// stand-in of the same kind). A round flange 120 mm across and 18 mm thick
// with a chamfer, a cylindrical sensor head 100 mm across up to 145 mm with
// a 3 mm deep window recess between z = 62 and 108 mm and a chamfered top,
// and a connector block (30 mm wide, 20 mm tall) standing 8 mm out of the
// head above the flange at +x: the only feature breaking the symmetry about
// the vertical axis. Bounding box 120 x 120 x 145 mm.
Mesh make_ls5() {
  Mesh m = revolve({{0, 0},
                    {60, 0},
                    {60, 18},
                    {56, 22},
                    {50, 22},
                    {50, 60},
                    {47, 62},
                    {47, 108},
                    {50, 110},
                    {50, 139},
                    {46, 145},
                    {0, 145}},
                   96);
  m.append(box_between(Vec3(44, -15, 30), Vec3(58, 15, 50)));
  return finish(m);
}

// Boletus (porcini-like) mushroom: a bulbous stem 50 mm across at its widest,
// tapering to 32 mm under the cap, and a thick domed cap 106 mm across, 110
// mm tall in all. Symmetric about z.
Mesh make_boletus() {
  return finish(revolve({{0, 0},
                         {14, 0},
                         {20, 2},
                         {24, 8},
                         {25, 16},
                         {23, 30},
                         {19, 45},
                         {16, 60},
                         {25, 61},
                         {40, 63},
                         {48, 66},
                         {52, 70},
                         {53, 75},
                         {52, 82},
                         {47, 92},
                         {38, 100},
                         {26, 106},
                         {13, 109},
                         {0, 110}},
                        64));
}

// EUR-like pallet, 1200 (x) x 800 (y) x 144 (z) mm: 3 bottom boards along x,
// 9 blocks 78 mm high, 3 cross boards along y, 5 deck boards along x, all 22
// mm thick. The blocks are inset by 1 mm so no two parts share an edge.
Mesh make_pallet() {
  Mesh m;
  const double L = 1200, W = 800, t = 22, block_h = 78;
  const double ys[3][2] = {{0, 100}, {W / 2 - 72.5, W / 2 + 72.5}, {W - 100, W}};  // bottom rows
  const double xs[3][2] = {{0, 145}, {L / 2 - 72.5, L / 2 + 72.5}, {L - 145, L}};  // block columns
  for (const auto& y : ys) m.append(box_between(Vec3(0, y[0], 0), Vec3(L, y[1], t)));
  for (const auto& x : xs)
    for (const auto& y : ys)
      m.append(box_between(Vec3(x[0] + 1, y[0] + 1, t), Vec3(x[1] - 1, y[1] - 1, t + block_h)));
  for (const auto& x : xs) m.append(box_between(Vec3(x[0], 0, t + block_h), Vec3(x[1], W, 2 * t + block_h)));
  const double widths[5] = {145, 100, 145, 100, 145};
  const double gap = (W - 635) / 4;
  double y = 0;
  for (double w : widths) {
    m.append(box_between(Vec3(0, y, 2 * t + block_h), Vec3(L, y + w, 3 * t + block_h)));
    y += w + gap;
  }
  return finish(m);
}

std::vector<std::string> procedural_kinds() {
  return {"box", "cylinder", "milk_carton", "ls5", "boletus", "pallet"};
}

Mesh make_procedural(const std::string& spec) {
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string args = colon == std::string::npos ? "" : spec.substr(colon + 1);
  const bool has_args = colon != std::string::npos;
  if (kind == "box") {
    if (!has_args) return make_box(100, 100, 100);
    const auto d = parse_dims(kind, args, 3);
    return make_box(d[0], d[1], d[2]);
  }
  if (kind == "cylinder") {
    if (!has_args) return make_cylinder(50, 100);
    const auto d = parse_dims(kind, args, 2);
    return make_cylinder(d[0] / 2, d[1]);
  }
  if (has_args)
    throw InputError("", "source", "generated model '" + kind + "' takes no size arguments (got '" + args + "')");
  if (kind == "milk_carton") return make_milk_carton();
  if (kind == "ls5") return make_ls5();
  if (kind == "boletus") return make_boletus();
  if (kind == "pallet") return make_pallet();
  std::string known;
  for (const auto& k : procedural_kinds()) known += (known.empty() ? "" : ", ") + k;
  throw InputError("", "source", "unknown generated model kind '" + kind + "' (known: " + known + ")");
}

}  // namespace pb
