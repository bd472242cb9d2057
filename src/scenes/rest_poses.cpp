#include "scenes/rest_poses.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <unordered_map>

namespace pb {

namespace {

struct HullFace {
  int v[3];
  Vec3 n;
  double d = 0;
  std::vector<int> outside;
  bool alive = true;
};

inline uint64_t edge_key(int a, int b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

class QuickHull {
 public:
  QuickHull(const std::vector<Vec3>& p) : P(p) {}

  std::vector<Eigen::Vector3i> run() {
    if (P.size() < 4 || !initial_simplex()) return {};
    // Every face in turn, the new ones too, until no point is outside any.
    for (size_t fi = 0; fi < faces.size(); ++fi)
      if (faces[fi].alive && !faces[fi].outside.empty()) add_farthest_point(static_cast<int>(fi));
    std::vector<Eigen::Vector3i> out;
    for (const auto& f : faces)
      if (f.alive) out.emplace_back(f.v[0], f.v[1], f.v[2]);
    return out;
  }

 private:
  // The first tetrahedron, from extreme points, with every other point
  // given to a face it lies outside of; false when the points are flat.
  bool initial_simplex() {
    const int n = static_cast<int>(P.size());
    Eigen::AlignedBox3d box;
    for (const auto& p : P) box.extend(p);
    const double diag = box.diagonal().norm();
    if (!(diag > 0)) return false;
    eps = 1e-6 * diag + 1e-9;
    int axis = 0;
    box.diagonal().maxCoeff(&axis);
    int i0 = 0, i1 = 0;
    for (int i = 0; i < n; ++i) {
      if (P[i][axis] < P[i0][axis]) i0 = i;
      if (P[i][axis] > P[i1][axis]) i1 = i;
    }
    int i2 = farthest_from_line(i0, i1);
    if (i2 < 0) return false;
    const Vec3 pn = (P[i1] - P[i0]).cross(P[i2] - P[i0]).normalized();
    const int i3 = farthest_from_plane(i0, pn);
    if (i3 < 0) return false;
    if (pn.dot(P[i3] - P[i0]) > 0) std::swap(i1, i2);  // i3 below plane (i0,i1,i2)
    add_face(i0, i1, i2);
    add_face(i0, i3, i1);
    add_face(i1, i3, i2);
    add_face(i2, i3, i0);
    for (int i = 0; i < n; ++i)
      if (i != i0 && i != i1 && i != i2 && i != i3) give_to_face_from(0, i);
    return true;
  }

  // The point farthest (beyond eps) from the line through points a and b, or -1.
  int farthest_from_line(int a, int b) const {
    const Vec3 dir = (P[b] - P[a]).normalized();
    int far = -1;
    double best = eps;
    for (int i = 0; i < static_cast<int>(P.size()); ++i) {
      const Vec3 w = P[i] - P[a];
      const double dist = (w - dir * dir.dot(w)).norm();
      if (dist > best) best = dist, far = i;
    }
    return far;
  }

  // The point farthest (beyond eps) from the plane through point a with unit
  // normal pn, on either side, or -1.
  int farthest_from_plane(int a, const Vec3& pn) const {
    int far = -1;
    double best = eps;
    for (int i = 0; i < static_cast<int>(P.size()); ++i) {
      const double dist = std::abs(pn.dot(P[i] - P[a]));
      if (dist > best) best = dist, far = i;
    }
    return far;
  }

  // Point i joins the outside list of the first face from `first` on that
  // it lies outside of (none: it is inside the hull).
  void give_to_face_from(size_t first, int i) {
    for (size_t f = first; f < faces.size(); ++f)
      if (dist(static_cast<int>(f), i) > eps) {
        faces[f].outside.push_back(i);
        break;
      }
  }

  // Adds face fi's farthest outside point (the eye) to the hull: the faces
  // it sees go, a cone from the eye to their horizon replaces them, and
  // their other outside points go to the new faces.
  void add_farthest_point(int fi) {
    int eye = -1;
    double far = -1;
    for (int i : faces[fi].outside) {
      const double d = dist(fi, i);
      if (d > far) far = d, eye = i;
    }
    std::vector<char> is_visible(faces.size(), 0);
    const std::vector<int> visible = faces_seen_from(fi, eye, is_visible);
    std::vector<std::pair<int, int>> horizon;  // edges (a, b) as oriented in the visible faces
    std::vector<int> orphans;
    for (int f : visible) {
      for (int k = 0; k < 3; ++k) {
        const int g = neighbour(f, k);
        if (g < 0 || !is_visible[g]) horizon.emplace_back(faces[f].v[k], faces[f].v[(k + 1) % 3]);
      }
      for (int i : faces[f].outside)
        if (i != eye) orphans.push_back(i);
    }
    for (int f : visible) remove_face(f);
    const size_t first_new = faces.size();
    for (const auto& e : horizon) add_face(e.first, e.second, eye);
    for (int i : orphans) give_to_face_from(first_new, i);
  }

  // The faces the eye sees, found by a flood fill over adjacency from face
  // fi (which it sees), each marked in is_visible.
  std::vector<int> faces_seen_from(int fi, int eye, std::vector<char>& is_visible) {
    stamp.resize(faces.size(), 0);
    ++stamp_id;
    std::vector<int> visible, stack{fi};
    stamp[fi] = stamp_id;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      if (dist(f, eye) <= eps) continue;
      is_visible[f] = 1;
      visible.push_back(f);
      for (int k = 0; k < 3; ++k) {
        const int g = neighbour(f, k);
        if (g >= 0 && stamp[g] != stamp_id) {
          stamp[g] = stamp_id;
          stack.push_back(g);
        }
      }
    }
    return visible;
  }

  void remove_face(int f) {
    faces[f].alive = false;
    faces[f].outside.clear();
    faces[f].outside.shrink_to_fit();
    for (int k = 0; k < 3; ++k) {
      auto it = edges.find(edge_key(faces[f].v[k], faces[f].v[(k + 1) % 3]));
      if (it != edges.end() && it->second == f) edges.erase(it);
    }
  }

  const std::vector<Vec3>& P;
  std::vector<HullFace> faces;
  std::unordered_map<uint64_t, int> edges;  // directed edge -> face
  double eps = 0;
  std::vector<int> stamp;  // per face: the flood fill that last reached it
  int stamp_id = 0;

  double dist(int f, int i) const { return faces[f].n.dot(P[i]) - faces[f].d; }
  int neighbour(int f, int k) const {
    const auto it = edges.find(edge_key(faces[f].v[(k + 1) % 3], faces[f].v[k]));
    return it == edges.end() ? -1 : it->second;
  }
  void add_face(int a, int b, int c) {
    HullFace f;
    f.v[0] = a, f.v[1] = b, f.v[2] = c;
    Vec3 n = (P[b] - P[a]).cross(P[c] - P[a]);
    const double l = n.norm();
    f.n = l > 0 ? Vec3(n / l) : Vec3::Zero();
    f.d = f.n.dot(P[a]);
    const int id = static_cast<int>(faces.size());
    faces.push_back(std::move(f));
    edges[edge_key(a, b)] = id;
    edges[edge_key(b, c)] = id;
    edges[edge_key(c, a)] = id;
  }
};

// Volume (times 6) and first moment (times 24) of a closed triangle set.
void volume_moment(const std::vector<Vec3>& V, const std::vector<Eigen::Vector3i>& F, double& vol6,
                   Vec3& moment24) {
  vol6 = 0;
  moment24.setZero();
  for (const auto& f : F) {
    const Vec3& a = V[f[0]];
    const Vec3& b = V[f[1]];
    const Vec3& c = V[f[2]];
    const double v = a.dot(b.cross(c));
    vol6 += v;
    moment24 += v * (a + b + c);
  }
}

double solid_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double num = std::abs(a.dot(b.cross(c)));
  const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2.0 * std::atan2(num, den);
}

}  // namespace

std::vector<Eigen::Vector3i> convex_hull_3d(const std::vector<Vec3>& points) {
  return QuickHull(points).run();
}

static Vec3 hull_centroid(const std::vector<Vec3>& V, const std::vector<Eigen::Vector3i>& H,
                          double* vol6_out) {
  double vol6;
  Vec3 m24;
  volume_moment(V, H, vol6, m24);
  if (vol6_out) *vol6_out = vol6;
  if (std::abs(vol6) < 1e-12) {
    Vec3 c = Vec3::Zero();
    for (const auto& v : V) c += v;
    return V.empty() ? c : Vec3(c / V.size());
  }
  return m24 / (4.0 * vol6);
}

Vec3 centre_of_mass(const Mesh& mesh) {
  std::vector<Vec3> V;
  V.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) V.push_back(v.cast<double>());
  const auto H = convex_hull_3d(V);
  double hull_vol6 = 0;
  const Vec3 hc = hull_centroid(V, H, &hull_vol6);
  double vol6;
  Vec3 m24;
  volume_moment(V, mesh.faces, vol6, m24);
  if (H.empty() || std::abs(vol6) < 0.02 * std::abs(hull_vol6)) return hc;
  const Vec3 c = m24 / (4.0 * vol6);
  // Must lie inside the hull (else the mesh is not a closed, consistent solid).
  for (const auto& f : H) {
    const Vec3 n = (V[f[1]] - V[f[0]]).cross(V[f[2]] - V[f[0]]);
    if (n.dot(c - V[f[0]]) > 0) return hc;
  }
  return c;
}

std::vector<Eigen::Vector2d> convex_hull_2d(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> h(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

bool convex_polygons_overlap(const std::vector<Eigen::Vector2d>& a,
                             const std::vector<Eigen::Vector2d>& b, double gap) {
  auto separated_on = [&](const std::vector<Eigen::Vector2d>& poly) {
    const size_t n = poly.size();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d e = poly[(i + 1) % n] - poly[i];
      Eigen::Vector2d axis(e.y(), -e.x());
      const double l = axis.norm();
      if (l <= 0) continue;
      axis /= l;
      double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
      for (const auto& p : a) amin = std::min(amin, axis.dot(p)), amax = std::max(amax, axis.dot(p));
      for (const auto& p : b) bmin = std::min(bmin, axis.dot(p)), bmax = std::max(bmax, axis.dot(p));
      if (amax + gap <= bmin || bmax + gap <= amin) return true;
    }
    return false;
  };
  if (a.empty() || b.empty()) return false;
  return !(separated_on(a) || separated_on(b));
}

namespace {

// The hull's triangles grouped into facets: adjacent coplanar triangles
// merged (union-find), each facet its triangles' indices.
std::map<int, std::vector<int>> coplanar_facets(const std::vector<Vec3>& V, const std::vector<Eigen::Vector3i>& H) {
  const int nf = static_cast<int>(H.size());
  std::vector<Vec3> normal(nf);
  for (int f = 0; f < nf; ++f)
    normal[f] = (V[H[f][1]] - V[H[f][0]]).cross(V[H[f][2]] - V[H[f][0]]).normalized();
  std::unordered_map<uint64_t, int> edge_face;
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) edge_face[edge_key(H[f][k], H[f][(k + 1) % 3])] = f;
  std::vector<int> parent(nf);
  std::iota(parent.begin(), parent.end(), 0);
  std::function<int(int)> find = [&](int x) { return parent[x] == x ? x : parent[x] = find(parent[x]); };
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto it = edge_face.find(edge_key(H[f][(k + 1) % 3], H[f][k]));
      if (it == edge_face.end()) continue;
      if (normal[f].dot(normal[it->second]) > 1.0 - 1e-6) parent[find(f)] = find(it->second);
    }
  std::map<int, std::vector<int>> groups;
  for (int f = 0; f < nf; ++f) groups[find(f)].push_back(f);
  return groups;
}

// The smallest distance of c inside the convex polygon (negative outside).
double margin_inside(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& c) {
  double margin = 1e300;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d e = poly[(i + 1) % poly.size()] - poly[i];
    const Eigen::Vector2d r = c - poly[i];
    margin = std::min(margin, (e.x() * r.y() - e.y() * r.x()) / e.norm());  // left of edge > 0
  }
  return margin;
}

// The rest pose on one facet (its triangles `members` of H), its
// probability the (unnormalized) solid angle of the facet seen from the
// centre of mass; false when the facet is degenerate or the centre of mass
// projects less than min_margin inside it.
bool rest_pose_on_facet(const std::vector<Vec3>& V, const std::vector<Eigen::Vector3i>& H,
                        const std::vector<int>& members, const Vec3& com, double min_margin, RestPose& rp) {
  // Area-weighted facet normal and its vertices.
  Vec3 n = Vec3::Zero();
  std::vector<int> verts;
  for (int f : members) {
    n += (V[H[f][1]] - V[H[f][0]]).cross(V[H[f][2]] - V[H[f][0]]);
    for (int k = 0; k < 3; ++k) verts.push_back(H[f][k]);
  }
  if (n.norm() <= 0) return false;
  n.normalize();
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  const Vec3 u = n.unitOrthogonal();
  const Vec3 w = n.cross(u);
  std::vector<Eigen::Vector2d> p2;
  double d = 0;
  for (int i : verts) {
    p2.emplace_back(u.dot(V[i]), w.dot(V[i]));
    d += n.dot(V[i]);
  }
  d /= verts.size();
  const auto poly = convex_hull_2d(p2);
  if (poly.size() < 3) return false;
  const double margin = margin_inside(poly, Eigen::Vector2d(u.dot(com), w.dot(com)));
  if (margin < min_margin) return false;
  // Solid angle of the facet polygon seen from the centre of mass.
  auto lift = [&](const Eigen::Vector2d& q) { return Vec3(u * q.x() + w * q.y() + n * d - com); };
  double omega = 0;
  const Vec3 a = lift(poly[0]);
  for (size_t i = 1; i + 1 < poly.size(); ++i) omega += solid_angle(a, lift(poly[i]), lift(poly[i + 1]));
  rp.normal = n;
  rp.probability = omega;
  rp.margin_mm = margin;
  rp.R_rest = Eigen::Quaterniond::FromTwoVectors(n, Vec3(0, 0, -1)).toRotationMatrix();
  return true;
}

}  // namespace

RestPoses compute_rest_poses(const Mesh& mesh, double min_margin_fraction) {
  RestPoses out;
  std::vector<Vec3> V;
  V.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) V.push_back(v.cast<double>());
  const auto H = convex_hull_3d(V);
  if (H.empty()) return out;
  const Vec3 com = centre_of_mass(mesh);
  out.centre_of_mass = com;
  Eigen::AlignedBox3d box;
  for (const auto& v : V) box.extend(v);
  const double min_margin = std::max(0.05, min_margin_fraction * box.diagonal().norm());
  double total = 0;
  for (const auto& [root, members] : coplanar_facets(V, H)) {
    RestPose rp;
    if (!rest_pose_on_facet(V, H, members, com, min_margin, rp)) continue;
    out.poses.push_back(rp);
    total += rp.probability;
  }
  if (out.poses.empty()) return out;
  for (auto& p : out.poses) p.probability /= total;
  std::stable_sort(out.poses.begin(), out.poses.end(),
                   [](const RestPose& a, const RestPose& b) { return a.probability > b.probability; });
  double best = std::cos(30.0 * M_PI / 180.0);
  for (size_t i = 0; i < out.poses.size(); ++i) {
    const double c = -out.poses[i].normal.z();
    if (c > best) best = c, out.upright = static_cast<int>(i);
  }
  return out;
}

int sample_rest_pose(const RestPoses& rp, double upright_probability, Rng& rng) {
  if (rp.poses.empty()) return -1;
  const double u = rng.uniform();
  if (rp.upright >= 0 && u < upright_probability) return rp.upright;
  const double x = rng.uniform();
  double acc = 0;
  for (size_t i = 0; i < rp.poses.size(); ++i) {
    acc += rp.poses[i].probability;
    if (x < acc) return static_cast<int>(i);
  }
  return static_cast<int>(rp.poses.size()) - 1;
}

}  // namespace pb
