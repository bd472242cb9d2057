// OSMesa depth renderer: see renderer.h for the method.
#include "render/renderer.h"

#include <GL/osmesa.h>

#include <GL/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/error.h"

namespace pb {

struct DepthRenderer::Impl {
  // A face plane in the camera frame: unit normal n, offset d (n.p = d).
  struct Plane {
    Vec3 n;
    double d;
    bool valid;
  };
  OSMesaContext ctx = nullptr;
  std::vector<uint8_t> color;     // RGBA, row 0 = bottom (OSMesa default Y_UP)
  std::vector<GLuint> depth;      // glReadPixels GL_UNSIGNED_INT, row 0 = bottom
  std::vector<float> positions;   // scratch: 3 vertices x 3 floats per face
  std::vector<uint8_t> colors;    // scratch: 3 vertices x RGBA per face
  std::vector<Plane> planes;      // scratch: per global face id
  std::vector<uint8_t> plane_done;

  // Draws every face flat in its id colour (base: see face_id_bases).
  void draw(const std::vector<RenderItem>& items, const std::vector<uint64_t>& base);
  // The plane of global face gid (of item `item`), computed once per render.
  const Plane& face_plane(const std::vector<RenderItem>& items, const std::vector<uint64_t>& base, size_t item,
                          uint64_t gid);
};

namespace {

// Mesa's llvmpipe rasterizes on helper threads (one per core) unless
// LP_NUM_THREADS says otherwise. Our renders are small and many, and the
// generator and `run` already keep every core busy with their own workers,
// so the helpers only add hand-offs: bench_generate's BM_TableAstra took
// 49.5 ms per image with them and 37.3 ms without (LP_NUM_THREADS=0, the
// same pixels). Set before main(), while the process has one thread, and
// only where the environment does not choose already.
const bool kRasterizeOnCallingThread = [] {
  setenv("LP_NUM_THREADS", "0", 0);
  return true;
}();

// Releases the calling thread's current context when leaving render().
struct ReleaseCurrent {
  ~ReleaseCurrent() { OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0); }
};

// Maps OpenCV camera coordinates (x right, y down, z forward) to GL clip
// coordinates such that the point projecting to pixel (u, v) lands on the
// centre of window pixel (u, H-1-v), and z_ndc runs from -1 (near) to 1 (far).
Mat4 projection(const Intrinsics& K, double n, double f) {
  const double W = K.width, H = K.height;
  Mat4 P = Mat4::Zero();
  P(0, 0) = 2.0 * K.fx / W;
  P(0, 2) = (2.0 * K.cx + 1.0) / W - 1.0;
  P(1, 1) = -2.0 * K.fy / H;
  P(1, 2) = 1.0 - (2.0 * K.cy + 1.0) / H;
  P(2, 2) = (f + n) / (f - n);
  P(2, 3) = -2.0 * f * n / (f - n);
  P(3, 2) = 1.0;
  return P;
}

// Global face ids: item i owns ids base[i]+1 .. base[i]+faces (0 = background).
std::vector<uint64_t> face_id_bases(const std::vector<RenderItem>& items) {
  std::vector<uint64_t> base(items.size() + 1, 0);
  for (size_t i = 0; i < items.size(); ++i) {
    const Mesh* m = items[i].mesh;
    if (!m) throw std::invalid_argument("RenderItem without a mesh");
    const int nv = static_cast<int>(m->vertices.size());
    for (const auto& face : m->faces)
      if (face.minCoeff() < 0 || face.maxCoeff() >= nv)
        throw std::invalid_argument("mesh face index out of range");
    base[i + 1] = base[i] + m->faces.size();
  }
  if (base.back() >= 0xFFFFFFFFull) throw std::invalid_argument("too many triangles to render");
  return base;
}

// Fixed-function state for id rendering, cleared buffers, projection P;
// without depth_test no depth buffer is used (the last face drawn wins).
void begin_frame(int W, int H, const Mat4& P, bool depth_test) {
  glViewport(0, 0, W, H);
  glDisable(GL_DITHER);
  glDisable(GL_LIGHTING);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_MULTISAMPLE);
  glDisable(GL_TEXTURE_2D);
  if (depth_test) glEnable(GL_DEPTH_TEST);
  else glDisable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(depth_test ? GL_TRUE : GL_FALSE);
  glShadeModel(GL_FLAT);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glClearColor(0.f, 0.f, 0.f, 0.f);
  glClearDepth(1.0);
  glClear(depth_test ? GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT : GL_COLOR_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  glLoadMatrixd(P.data());  // Eigen is column-major, as GL expects
}

}  // namespace

void DepthRenderer::Impl::draw(const std::vector<RenderItem>& items, const std::vector<uint64_t>& base) {
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
  for (size_t i = 0; i < items.size(); ++i) {
    const Mesh& m = *items[i].mesh;
    if (m.faces.empty()) continue;
    const Mat4 T = items[i].T_cam_model.matrix();
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(T.data());
    const size_t nf = m.faces.size();
    positions.resize(nf * 9);
    colors.resize(nf * 12);
    float* pos = positions.data();
    uint8_t* col = colors.data();
    for (size_t k = 0; k < nf; ++k) {
      const uint32_t id = static_cast<uint32_t>(base[i] + k + 1);
      const uint8_t rgba[4] = {static_cast<uint8_t>(id & 0xFF), static_cast<uint8_t>((id >> 8) & 0xFF),
                               static_cast<uint8_t>((id >> 16) & 0xFF), static_cast<uint8_t>(id >> 24)};
      for (int c = 0; c < 3; ++c) {
        const Vec3f& p = m.vertices[m.faces[k][c]];
        pos[9 * k + 3 * c + 0] = p.x();
        pos[9 * k + 3 * c + 1] = p.y();
        pos[9 * k + 3 * c + 2] = p.z();
        for (int j = 0; j < 4; ++j) col[12 * k + 4 * c + j] = rgba[j];
      }
    }
    glVertexPointer(3, GL_FLOAT, 0, pos);
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, col);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(nf * 3));
  }
  glDisableClientState(GL_COLOR_ARRAY);
  glDisableClientState(GL_VERTEX_ARRAY);
}

const DepthRenderer::Impl::Plane& DepthRenderer::Impl::face_plane(const std::vector<RenderItem>& items,
                                                                  const std::vector<uint64_t>& base, size_t item,
                                                                  uint64_t gid) {
  Plane& pl = planes[gid];
  if (plane_done[gid]) return pl;
  const Mesh& m = *items[item].mesh;
  const Eigen::Vector3i& fc = m.faces[gid - base[item]];
  const Pose& T = items[item].T_cam_model;
  const Vec3 a = T * m.vertices[fc[0]].cast<double>();
  const Vec3 b = T * m.vertices[fc[1]].cast<double>();
  const Vec3 c = T * m.vertices[fc[2]].cast<double>();
  Vec3 nn = (b - a).cross(c - a);
  const double len = nn.norm();
  pl.valid = len > 0 && std::isfinite(len);
  if (pl.valid) {
    nn /= len;
    pl.n = nn;
    pl.d = nn.dot(a);
  }
  plane_done[gid] = 1;
  return pl;
}

DepthRenderer::DepthRenderer(const Intrinsics& K, RenderSettings settings)
    : impl_(std::make_unique<Impl>()), K_(K), settings_(settings) {
  if (K.width <= 0 || K.height <= 0 || K.width > 16384 || K.height > 16384)
    throw InputError("", "intrinsics", "image size must be 1..16384 pixels, got " +
                                           std::to_string(K.width) + "x" + std::to_string(K.height));
  if (!(K.fx > 0) || !(K.fy > 0) || !std::isfinite(K.cx) || !std::isfinite(K.cy))
    throw InputError("", "intrinsics", "focal lengths must be positive and the principal point finite");
  if (!(settings.near_mm > 0) || !(settings.far_mm > settings.near_mm))
    throw InputError("", "render", "need 0 < near_mm < far_mm");
  impl_->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (!impl_->ctx) throw std::runtime_error("OSMesaCreateContextExt failed");
  const size_t n = static_cast<size_t>(K.width) * K.height;
  impl_->color.assign(n * 4, 0);
  impl_->depth.assign(n, 0);
}

DepthRenderer::~DepthRenderer() {
  if (impl_ && impl_->ctx) OSMesaDestroyContext(impl_->ctx);
}

std::vector<uint64_t> DepthRenderer::rasterize(const std::vector<RenderItem>& items, bool depth_test,
                                               bool read_depth) {
  const int W = K_.width, H = K_.height;
  std::vector<uint64_t> base = face_id_bases(items);
  if (!OSMesaMakeCurrent(impl_->ctx, impl_->color.data(), GL_UNSIGNED_BYTE, W, H))
    throw std::runtime_error("OSMesaMakeCurrent failed");
  ReleaseCurrent release;
  begin_frame(W, H, projection(K_, settings_.near_mm, settings_.far_mm), depth_test);
  impl_->draw(items, base);
  glFinish();
  if (read_depth) glReadPixels(0, 0, W, H, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, impl_->depth.data());
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) throw std::runtime_error("OpenGL error " + std::to_string(err) + " while rendering");
  return base;
}

namespace {

// The face id of GL pixel gl of an RGBA id buffer (0 = background): R is
// its lowest byte, A its highest.
inline uint32_t face_id(const uint8_t* col, size_t gl) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  uint32_t id;
  std::memcpy(&id, col + 4 * gl, 4);
  return id;
#else
  return uint32_t(col[4 * gl]) | (uint32_t(col[4 * gl + 1]) << 8) | (uint32_t(col[4 * gl + 2]) << 16) |
         (uint32_t(col[4 * gl + 3]) << 24);
#endif
}

// The item owning global face id gid (base: face_id_bases); items.size()
// or more for an id past the last item's faces.
inline size_t item_of_face(const std::vector<uint64_t>& base, uint64_t gid) {
  return static_cast<size_t>(std::upper_bound(base.begin(), base.end(), gid) - base.begin() - 1);
}

}  // namespace

std::vector<int32_t> DepthRenderer::render_labels(const std::vector<RenderItem>& items, bool overlap) {
  const int W = K_.width, H = K_.height;
  const std::vector<uint64_t> base = rasterize(items, /*depth_test=*/overlap, /*read_depth=*/false);
  std::vector<int32_t> labels(static_cast<size_t>(W) * H, -1);
  uint64_t last_gid = ~uint64_t(0);
  size_t item = 0;
  const uint8_t* col = impl_->color.data();
  for (int v = 0; v < H; ++v) {
    const size_t gl_row = static_cast<size_t>(H - 1 - v) * W;  // GL row 0 is the bottom row
    int32_t* out = labels.data() + static_cast<size_t>(v) * W;
    for (int u = 0; u < W; ++u) {
      const uint32_t id = face_id(col, gl_row + u);
      if (id == 0) continue;
      const uint64_t gid = id - 1;
      if (gid != last_gid) {
        item = item_of_face(base, gid);
        last_gid = gid;
      }
      if (item < items.size()) out[u] = items[item].label;
    }
  }
  return labels;
}

RenderOutput DepthRenderer::render(const std::vector<RenderItem>& items) {
  const int W = K_.width, H = K_.height;
  const double n = settings_.near_mm, f = settings_.far_mm;
  const std::vector<uint64_t> base = rasterize(items, /*depth_test=*/true, /*read_depth=*/true);

  RenderOutput out;
  out.depth = DepthImage(W, H);
  out.labels.assign(static_cast<size_t>(W) * H, -1);
  if (settings_.normals) out.normals.assign(static_cast<size_t>(W) * H, Vec3f::Zero());

  // Face planes in the camera frame, computed lazily for the visible faces.
  const bool need_planes = settings_.exact_depth || settings_.normals;
  if (need_planes) {
    impl_->planes.resize(base.back());
    impl_->plane_done.assign(base.back(), 0);
  }

  const double zA = f + n, zB = f - n, zC = 2.0 * f * n;
  // The viewing ray's x of every column and y of every row (the same values
  // as computing them per pixel).
  std::vector<double> ray_x(static_cast<size_t>(W)), ray_y(static_cast<size_t>(H));
  for (int u = 0; u < W; ++u) ray_x[static_cast<size_t>(u)] = (u - K_.cx) / K_.fx;
  for (int v = 0; v < H; ++v) ray_y[static_cast<size_t>(v)] = (v - K_.cy) / K_.fy;
  // The face of the previous pixel: neighbouring pixels mostly share one.
  uint64_t last_gid = ~uint64_t(0);
  size_t item = 0;
  const Impl::Plane* pl = nullptr;
  const uint8_t* col = impl_->color.data();
  for (int v = 0; v < H; ++v) {
    const int row = H - 1 - v;  // GL row 0 is the bottom row
    for (int u = 0; u < W; ++u) {
      const size_t gl = static_cast<size_t>(row) * W + u;
      const uint32_t id = face_id(col, gl);
      if (id == 0) continue;
      const uint64_t gid = id - 1;
      if (gid != last_gid) {
        item = item_of_face(base, gid);
        pl = item < items.size() && need_planes ? &impl_->face_plane(items, base, item, gid) : nullptr;
        last_gid = gid;
      }
      if (item >= items.size()) continue;  // cannot happen with an intact colour buffer
      const size_t px = static_cast<size_t>(v) * W + u;
      const double dn = impl_->depth[gl] / 4294967295.0;
      const double z_ndc = 2.0 * dn - 1.0;
      double z = zC / (zA - z_ndc * zB);
      out.labels[px] = items[item].label;
      if (pl && pl->valid) {
        const Vec3 ray(ray_x[static_cast<size_t>(u)], ray_y[static_cast<size_t>(v)], 1.0);
        const double denom = pl->n.dot(ray);
        if (settings_.exact_depth && std::abs(denom) > 1e-12) {
          const double ze = pl->d / denom;
          // Guard against extrapolation far off the face at extreme grazing
          // angles: keep the buffer value unless the two agree.
          if (ze > 0 && std::abs(ze - z) < 1.0 + 1e-3 * z) z = ze;
        }
        if (settings_.normals) {
          const Vec3 nc = denom > 0 ? Vec3(-pl->n) : pl->n;
          out.normals[px] = nc.cast<float>();
        }
      }
      out.depth.z[px] = static_cast<float>(z);
    }
  }
  return out;
}

}  // namespace pb
