#include "gesture_formation/render/renderer.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

namespace gesture_formation::render {

namespace {

using Eigen::Matrix3d;
using Eigen::Matrix4f;
using Eigen::Vector3d;

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_p;
layout(location = 1) in vec3 a_n;
layout(location = 2) in vec3 a_c;
uniform mat4 u_model;      // object → world
uniform mat4 u_view;       // world → optical frame
uniform mat4 u_proj;       // optical frame → clip
out vec3 v_world;
out vec3 v_normal;
out vec3 v_colour;
out float v_z;
void main() {
  vec4 w = u_model * vec4(a_p, 1.0);
  vec4 c = u_view * w;
  v_world = w.xyz;
  v_normal = mat3(u_model) * a_n;
  v_colour = a_c;
  v_z = c.z;
  gl_Position = u_proj * c;
}
)";

const char* kFragmentShader = R"(#version 330 core
in vec3 v_world;
in vec3 v_normal;
in vec3 v_colour;
in float v_z;
uniform int u_material;    // 0: vertex colour, 1: ground
uniform float u_class;     // PixelClass / 255
uniform vec3 u_sun;        // towards the sun, unit
uniform vec3 u_eye;        // camera centre, world
layout(location = 0) out vec4 o_colour;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_class;
float hash(vec2 p) {                 // sine-free hash (cheap on llvmpipe)
  vec3 q = fract(vec3(p.xyx) * 0.1031);
  q += dot(q, q.yzx + 33.33);
  return fract((q.x + q.y) * q.z);
}
float noise(vec2 p) {
  vec2 i = floor(p), f = fract(p);
  vec2 u = f * f * (3.0 - 2.0 * f);
  return mix(mix(hash(i), hash(i + vec2(1, 0)), u.x), mix(hash(i + vec2(0, 1)), hash(i + vec2(1, 1)), u.x), u.y);
}
void main() {
  vec3 n = normalize(v_normal);
  vec3 to_eye = normalize(u_eye - v_world);
  if (dot(n, to_eye) < 0.0) n = -n;   // two-sided
  vec3 base = v_colour;
  if (u_material == 1) {               // grass and gravel patches, 0.3 m and 4 m scales
    float big = noise(v_world.xy * 0.25), small = noise(v_world.xy * 3.0), fine = hash(floor(v_world.xy * 17.0));
    vec3 grass = vec3(0.30, 0.42, 0.18), dry = vec3(0.52, 0.50, 0.34), gravel = vec3(0.48, 0.46, 0.43);
    base = mix(grass, dry, smoothstep(0.35, 0.75, big));
    base = mix(base, gravel, smoothstep(0.72, 0.9, noise(v_world.xy * 0.07 + 7.0)));
    base *= 0.80 + 0.25 * small + 0.10 * (fine - 0.5);
  }
  float diffuse = max(dot(n, u_sun), 0.0);
  vec3 lit = base * (0.45 + 0.65 * diffuse) + 0.06 * pow(max(dot(reflect(-u_sun, n), to_eye), 0.0), 16.0);
  o_colour = vec4(clamp(lit, 0.0, 1.0), 1.0);
  o_depth = v_z;
  o_class = u_class;
}
)";

const char* kSkyVertexShader = R"(#version 330 core
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(p, 1.0, 1.0);  // on the far plane: drawn last, only where nothing else is
}
)";

const char* kSkyFragmentShader = R"(#version 330 core
uniform mat3 u_ray;        // pixel (u, v, 1) → world ray direction (R_world_camera K^-1)
uniform vec3 u_sun;
layout(location = 0) out vec4 o_colour;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_class;
void main() {
  vec3 d = normalize(u_ray * vec3(gl_FragCoord.x - 0.5, gl_FragCoord.y - 0.5, 1.0));
  float e = clamp(d.z, -0.2, 1.0);
  vec3 horizon = vec3(0.80, 0.86, 0.92), zenith = vec3(0.32, 0.52, 0.85);
  vec3 c = mix(horizon, zenith, pow(max(e, 0.0), 0.6));
  c += vec3(0.25, 0.22, 0.15) * pow(max(dot(d, u_sun), 0.0), 200.0);
  o_colour = vec4(clamp(c, 0.0, 1.0), 1.0);
  o_depth = uintBitsToFloat(0x7fc00000u);   // NaN: nothing
  o_class = 0.0;
}
)";

/// Column-major float matrix for glUniformMatrix4fv.
Matrix4f toGl(const Eigen::Matrix4d& m) { return m.cast<float>(); }

/// Optical frame → clip: GL's window y equals the image row v, so that glReadPixels' first
/// row is the image's top row; pixel centres (window i + 0.5) map to OpenCV's integer u, v.
Eigen::Matrix4d projection(const estimation::CameraIntrinsics& k, double n, double f) {
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  const double W = k.width_px, H = k.height_px;
  P(0, 0) = 2.0 * k.fx / W;
  P(0, 2) = 2.0 * (k.cx + 0.5) / W - 1.0;
  P(1, 1) = 2.0 * k.fy / H;
  P(1, 2) = 2.0 * (k.cy + 0.5) / H - 1.0;
  P(2, 2) = (f + n) / (f - n);
  P(2, 3) = -2.0 * f * n / (f - n);
  P(3, 2) = 1.0;
  return P;
}

std::string eglErrorText() {
  std::ostringstream s;
  s << "EGL error 0x" << std::hex << eglGetError();
  return s.str();
}

GLuint compile(GLenum type, const char* src, std::string* error) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof(log), nullptr, log);
    *error = std::string("shader compilation failed: ") + log;
  }
  return s;
}

GLuint link(const char* vs, const char* fs, std::string* error) {
  const GLuint v = compile(GL_VERTEX_SHADER, vs, error), f = compile(GL_FRAGMENT_SHADER, fs, error);
  const GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok && error->empty()) {
    char log[2048];
    glGetProgramInfoLog(p, sizeof(log), nullptr, log);
    *error = std::string("shader link failed: ") + log;
  }
  glDeleteShader(v);
  glDeleteShader(f);
  return p;
}

/// A mesh on the GPU.
struct GpuMesh {
  GLuint vao = 0, vbo = 0, ibo = 0;
  GLsizei count = 0;
  std::size_t vbo_bytes = 0, ibo_bytes = 0;
  /// `same_indices`: the caller promises the index list is unchanged when its size is (a posed
  /// worker); otherwise the indices are sent again whenever they are uploaded.
  void upload(const TriangleMesh& m, GLenum usage, bool same_indices = true) {
    if (vao == 0) {
      glGenVertexArrays(1, &vao);
      glGenBuffers(1, &vbo);
      glGenBuffers(1, &ibo);
      glBindVertexArray(vao);
      glBindBuffer(GL_ARRAY_BUFFER, vbo);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
      for (GLuint a = 0; a < 3; ++a) {
        glEnableVertexAttribArray(a);
        glVertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<const void*>(a * 3 * sizeof(float)));
      }
    }
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    const std::size_t vb = m.vertices.size() * sizeof(Vertex), ib = m.indices.size() * sizeof(std::uint32_t);
    if (vb != vbo_bytes) {
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vb), m.vertices.data(), usage);
      vbo_bytes = vb;
    } else if (vb > 0) {
      glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(vb), m.vertices.data());
    }
    if (ib != ibo_bytes) {
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(ib), m.indices.data(), usage);
      ibo_bytes = ib;
    } else if (!same_indices && ib > 0) {
      glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(ib), m.indices.data());
    }
    count = static_cast<GLsizei>(m.indices.size());
  }
  void draw() const {
    if (count == 0) return;
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, nullptr);
  }
  void release() {
    if (vao != 0) {
      glDeleteBuffers(1, &vbo);
      glDeleteBuffers(1, &ibo);
      glDeleteVertexArrays(1, &vao);
    }
    vao = vbo = ibo = 0;
  }
};

}  // namespace

std::vector<std::string> RendererConfig::validate() const {
  std::vector<std::string> e;
  if (!(near_m > 0.0)) e.push_back("render.near_m must be > 0, got " + std::to_string(near_m));
  if (!(far_m > near_m)) e.push_back("render.far_m must be > near_m, got " + std::to_string(far_m));
  if (!(sun_direction_world.allFinite() && sun_direction_world.norm() > 1e-9)) e.push_back("render.sun_direction_world must be non-zero and finite");
  if (!(ground_half_size_m > 0.0)) e.push_back("render.ground_half_size_m must be > 0, got " + std::to_string(ground_half_size_m));
  if (!(joint_visibility_margin_m > 0.0)) e.push_back("render.joint_visibility_margin_m must be > 0, got " + std::to_string(joint_visibility_margin_m));
  return e;
}

Eigen::Isometry3d cameraPoseFromHeadingPitch(const Vector3d& p_world, double heading_rad, double pitch_rad) {
  const Vector3d z(std::cos(pitch_rad) * std::cos(heading_rad), std::cos(pitch_rad) * std::sin(heading_rad), std::sin(pitch_rad));
  const Vector3d x(std::sin(heading_rad), -std::cos(heading_rad), 0.0);  // right: forward × up, horizontal
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);  // down
  T.linear().col(2) = z;
  T.translation() = p_world;
  return T;
}

struct Renderer::Impl {
  RendererConfig config;
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  std::string gl_renderer;
  GLuint program = 0, sky_program = 0, sky_vao = 0;
  GLuint fbo = 0, rb_colour = 0, rb_depth_m = 0, rb_class = 0, rb_z = 0;
  int fb_width = 0, fb_height = 0;
  GpuMesh world, site, ground, uav, worker;
  std::shared_ptr<WorkerMesh> worker_mesh;
  bool worker_set = false;
  PosedKeypoints worker_keypoints;   ///< the worker's, kept apart from the bystanders' posing
  std::vector<GpuMesh> bystanders;   ///< allocated as needed, released with the renderer
  std::size_t bystander_count = 0;   ///< of the last setBystanders
  cv::Mat rgba;  ///< read-back buffer, reused
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> uavs;

  bool makeCurrent() const { return eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) == EGL_TRUE; }
  std::string initEgl();
  std::string initGl();
  void ensureFramebuffer(int w, int h);
  void setUniforms(GLuint prog, const Eigen::Matrix4d& model, const Eigen::Matrix4d& view, const Eigen::Matrix4d& proj,
                   int material, PixelClass cls, const Vector3d& eye) const;
  WorkerTruth truth(const CameraView& cam, const RenderedFrame& f) const;
  void drawScene(const CameraView& cam, std::optional<std::size_t> skip_uav);
  void readBack(int width, int height, RenderedFrame& f);
  ~Impl() {
    if (display == EGL_NO_DISPLAY) return;
    if (context != EGL_NO_CONTEXT && makeCurrent()) {
      for (GpuMesh* m : {&world, &site, &ground, &uav, &worker}) m->release();
      for (GpuMesh& m : bystanders) m.release();
      if (fbo != 0) {
        glDeleteFramebuffers(1, &fbo);
        GLuint rbs[4] = {rb_colour, rb_depth_m, rb_class, rb_z};
        glDeleteRenderbuffers(4, rbs);
      }
      if (sky_vao != 0) glDeleteVertexArrays(1, &sky_vao);
      if (program != 0) glDeleteProgram(program);
      if (sky_program != 0) glDeleteProgram(sky_program);
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
    }
    // No eglTerminate: an EGL display is one per process, shared with every other Renderer.
  }
};

std::string Renderer::Impl::initEgl() {
  const std::string how = " (headless rendering needs Mesa's EGL: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri, "
                          "as tools/setup.sh does; docs/rendering.md)";
  const char* ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const std::string client_ext = ext != nullptr ? ext : "";
  if (client_ext.find("EGL_MESA_platform_surfaceless") != std::string::npos) {
    const auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display != nullptr) display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  }
  if (display == EGL_NO_DISPLAY) display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (display == EGL_NO_DISPLAY) return "no EGL display (neither the surfaceless platform nor a default display)" + how;
  EGLint major = 0, minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
    const std::string e = eglErrorText();
    display = EGL_NO_DISPLAY;
    return "eglInitialize failed: " + e + how;
  }
  const EGLint attrs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig cfg = nullptr;
  EGLint n = 0;
  if (eglChooseConfig(display, attrs, &cfg, 1, &n) != EGL_TRUE || n < 1) return "no EGL config with desktop OpenGL" + how;
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) return "eglBindAPI(EGL_OPENGL_API) failed: " + eglErrorText() + how;
  const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  context = eglCreateContext(display, cfg, EGL_NO_CONTEXT, ctx_attrs);
  if (context == EGL_NO_CONTEXT) return "no OpenGL 3.3 core context: " + eglErrorText() + how;
  if (!makeCurrent()) return "eglMakeCurrent without a surface failed (EGL_KHR_surfaceless_context): " + eglErrorText() + how;
  const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  gl_renderer = r != nullptr ? r : "?";
  return "";
}

std::string Renderer::Impl::initGl() {
  std::string error;
  program = link(kVertexShader, kFragmentShader, &error);
  if (!error.empty()) return error;
  sky_program = link(kSkyVertexShader, kSkyFragmentShader, &error);
  if (!error.empty()) return error;
  glGenVertexArrays(1, &sky_vao);
  // the ground: one big square (its texture is procedural), and the UAV model
  return "";
}

void Renderer::Impl::ensureFramebuffer(int w, int h) {
  if (fbo != 0 && w == fb_width && h == fb_height) return;
  if (fbo == 0) {
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &rb_colour);
    glGenRenderbuffers(1, &rb_depth_m);
    glGenRenderbuffers(1, &rb_class);
    glGenRenderbuffers(1, &rb_z);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  const std::array<std::pair<GLuint, GLenum>, 4> rbs{{{rb_colour, GL_RGBA8}, {rb_depth_m, GL_R32F}, {rb_class, GL_R8}, {rb_z, GL_DEPTH_COMPONENT32F}}};
  for (std::size_t i = 0; i < rbs.size(); ++i) {
    glBindRenderbuffer(GL_RENDERBUFFER, rbs[i].first);
    glRenderbufferStorage(GL_RENDERBUFFER, rbs[i].second, w, h);
    const GLenum at = i == 3 ? GL_DEPTH_ATTACHMENT : static_cast<GLenum>(GL_COLOR_ATTACHMENT0 + i);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, at, GL_RENDERBUFFER, rbs[i].first);
  }
  const GLenum bufs[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  glDrawBuffers(3, bufs);
  fb_width = w;
  fb_height = h;
}

void Renderer::Impl::setUniforms(GLuint prog, const Eigen::Matrix4d& model, const Eigen::Matrix4d& view,
                                 const Eigen::Matrix4d& proj, int material, PixelClass cls, const Vector3d& eye) const {
  const Matrix4f m = toGl(model), v = toGl(view), p = toGl(proj);
  glUniformMatrix4fv(glGetUniformLocation(prog, "u_model"), 1, GL_FALSE, m.data());
  glUniformMatrix4fv(glGetUniformLocation(prog, "u_view"), 1, GL_FALSE, v.data());
  glUniformMatrix4fv(glGetUniformLocation(prog, "u_proj"), 1, GL_FALSE, p.data());
  glUniform1i(glGetUniformLocation(prog, "u_material"), material);
  glUniform1f(glGetUniformLocation(prog, "u_class"), static_cast<float>(static_cast<int>(cls)) / 255.0f);
  const Eigen::Vector3f sun = config.sun_direction_world.normalized().cast<float>(), e = eye.cast<float>();
  glUniform3fv(glGetUniformLocation(prog, "u_sun"), 1, sun.data());
  glUniform3fv(glGetUniformLocation(prog, "u_eye"), 1, e.data());
}

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

common::Result<std::unique_ptr<Renderer>> Renderer::create(const RendererConfig& config) {
  using R = common::Result<std::unique_ptr<Renderer>>;
  const auto problems = config.validate();
  if (!problems.empty()) {
    std::string all;
    for (const auto& p : problems) all += (all.empty() ? "" : "; ") + p;
    return R::fail(all);
  }
  auto impl = std::make_unique<Impl>();
  impl->config = config;
  if (!config.worker_asset_path.empty()) {
    auto mesh = WorkerMesh::load(config.worker_asset_path);
    if (!mesh) return R::fail(mesh.reason());
    impl->worker_mesh = *mesh;
  }
  std::string e = impl->initEgl();
  if (e.empty()) e = impl->initGl();
  if (!e.empty()) return R::fail(e);
  impl->uav.upload(quadrotorMesh(), GL_STATIC_DRAW);
  return R::ok(std::unique_ptr<Renderer>(new Renderer(std::move(impl))));
}

common::Result<bool> Renderer::setWorldMesh(const TriangleMesh& obstacles, double ground_z_m, const Vector3d& centre_world) {
  using R = common::Result<bool>;
  if (!std::isfinite(ground_z_m) || !centre_world.allFinite()) return R::fail("render world: ground height and centre must be finite");
  if (!impl_->makeCurrent()) return R::fail("eglMakeCurrent failed: " + eglErrorText());
  impl_->world.upload(obstacles, GL_STATIC_DRAW);
  TriangleMesh g;
  const double h = impl_->config.ground_half_size_m;
  const Rgb white(1.0f, 1.0f, 1.0f);
  for (int k = 0; k < 4; ++k) {
    const double x = centre_world.x() + ((k == 1 || k == 2) ? h : -h), y = centre_world.y() + (k >= 2 ? h : -h);
    Vertex v{};
    v.p[0] = static_cast<float>(x), v.p[1] = static_cast<float>(y), v.p[2] = static_cast<float>(ground_z_m);
    v.n[2] = 1.0f;
    for (int i = 0; i < 3; ++i) v.c[i] = white[i];
    g.vertices.push_back(v);
  }
  g.indices = {0, 1, 2, 0, 2, 3};
  impl_->ground.upload(g, GL_STATIC_DRAW);
  return R::ok(true);
}

common::Result<bool> Renderer::setSiteObstacles(const TriangleMesh& obstacles) {
  using R = common::Result<bool>;
  for (const Vertex& v : obstacles.vertices) {
    if (!std::isfinite(v.p[0]) || !std::isfinite(v.p[1]) || !std::isfinite(v.p[2])) return R::fail("site obstacles: a vertex is not finite");
  }
  for (const std::uint32_t i : obstacles.indices) {
    if (i >= obstacles.vertices.size()) return R::fail("site obstacles: index " + std::to_string(i) + " beyond the vertices");
  }
  if (!impl_->makeCurrent()) return R::fail("eglMakeCurrent failed: " + eglErrorText());
  impl_->site.upload(obstacles, GL_DYNAMIC_DRAW, /*same_indices=*/false);
  return R::ok(true);
}

common::Result<bool> Renderer::setWorld(const planning::Scenario& scenario) {
  const Vector3d centre = 0.5 * (scenario.map.bounds.min_world + scenario.map.bounds.max_world);
  return setWorldMesh(obstacleMesh(scenario), scenario.ground.enabled ? scenario.ground.height_m : 0.0, centre);
}

common::Result<bool> Renderer::setWorker(const WorkerJoints& joints, double height_m, const Appearance& appearance) {
  using R = common::Result<bool>;
  if (!impl_->worker_mesh) return R::fail("no worker asset: RendererConfig.worker_asset_path is empty");
  const auto problems = appearance.validate();
  if (!problems.empty()) return R::fail(problems.front());
  impl_->worker_mesh->dress(appearance);
  const auto posed = impl_->worker_mesh->pose(joints, height_m);
  if (!posed) return posed;
  if (!impl_->makeCurrent()) return R::fail("eglMakeCurrent failed: " + eglErrorText());
  impl_->worker.upload(impl_->worker_mesh->mesh(), GL_DYNAMIC_DRAW);
  impl_->worker_keypoints = impl_->worker_mesh->keypoints();
  impl_->worker_set = true;
  return R::ok(true);
}

void Renderer::clearWorker() { impl_->worker_set = false; }

common::Result<bool> Renderer::setBystanders(const std::vector<Bystander>& people) {
  using R = common::Result<bool>;
  if (people.size() > kMaxBystanders) {
    return R::fail("bystanders: at most " + std::to_string(kMaxBystanders) + ", got " + std::to_string(people.size()));
  }
  if (!people.empty() && !impl_->worker_mesh) return R::fail("no worker asset: RendererConfig.worker_asset_path is empty");
  for (std::size_t i = 0; i < people.size(); ++i) {
    const auto problems = people[i].appearance.validate();
    if (!problems.empty()) return R::fail("bystander " + std::to_string(i) + ": " + problems.front());
  }
  if (!impl_->makeCurrent()) return R::fail("eglMakeCurrent failed: " + eglErrorText());
  if (impl_->bystanders.size() < people.size()) impl_->bystanders.resize(people.size());
  for (std::size_t i = 0; i < people.size(); ++i) {
    impl_->worker_mesh->dress(people[i].appearance);
    const auto posed = impl_->worker_mesh->pose(people[i].joints, people[i].height_m);
    if (!posed) {
      impl_->bystander_count = 0;
      return R::fail("bystander " + std::to_string(i) + ": " + posed.reason());
    }
    impl_->bystanders[i].upload(impl_->worker_mesh->mesh(), GL_DYNAMIC_DRAW);
  }
  impl_->bystander_count = people.size();
  return R::ok(true);
}

void Renderer::setUavs(const std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>& T_world_body) {
  impl_->uavs = T_world_body;
}

const std::string& Renderer::glRenderer() const { return impl_->gl_renderer; }
const PosedKeypoints* Renderer::workerKeypoints() const { return impl_->worker_set ? &impl_->worker_keypoints : nullptr; }

WorkerTruth Renderer::Impl::truth(const CameraView& cam, const RenderedFrame& f) const {
  WorkerTruth t;
  if (!worker_set) return t;
  t.drawn = true;
  const estimation::CameraModel model(cam.intrinsics);
  const Eigen::Isometry3d T_camera_world = cam.T_world_camera.inverse();
  const PosedKeypoints& kp = worker_keypoints;
  for (int k = 0; k < gesture::kNumKeypoints; ++k) {
    auto& out = t.keypoints[static_cast<std::size_t>(k)];
    const Vector3d p_cam = T_camera_world * kp.p_world[static_cast<std::size_t>(k)];
    out.depth_m = p_cam.z();
    const auto uv = model.project(p_cam);
    if (!uv) continue;
    out.uv_px = *uv;
    out.in_image = model.inImage(*uv + Eigen::Vector2d(0.5, 0.5));  // pixel (round) inside the image
    if (!out.in_image) continue;
    const int u = static_cast<int>(std::lround(uv->x())), v = static_cast<int>(std::lround(uv->y()));
    if (u < 0 || v < 0 || u >= f.depth_m.cols || v >= f.depth_m.rows) {
      out.in_image = false;
      continue;
    }
    const float seen = f.depth_m.at<float>(v, u);
    const double margin = kp.on_surface[static_cast<std::size_t>(k)] ? 0.06 : config.joint_visibility_margin_m;
    out.visible = std::isfinite(seen) && seen >= p_cam.z() - margin;
  }
  cv::Mat mask = f.classes == static_cast<int>(PixelClass::kWorker);
  t.visible_pixels = cv::countNonZero(mask);
  if (t.visible_pixels > 0) t.visible_box_px = cv::boundingRect(mask);
  return t;
}

void Renderer::Impl::drawScene(const CameraView& cam, std::optional<std::size_t> skip_uav) {
  const auto& k = cam.intrinsics;
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, k.width_px, k.height_px);
  glDisable(GL_CULL_FACE);
  glClearDepth(1.0);
  glClear(GL_DEPTH_BUFFER_BIT);
  // the world with depth test, then the sky where nothing was drawn (each pixel shaded once)
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glUseProgram(program);
  const Eigen::Matrix4d view = cam.T_world_camera.inverse().matrix();
  const Eigen::Matrix4d proj = projection(k, config.near_m, config.far_m);
  const Vector3d eye = cam.T_world_camera.translation();
  const Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
  setUniforms(program, I, view, proj, 1, PixelClass::kGround, eye);
  ground.draw();
  setUniforms(program, I, view, proj, 0, PixelClass::kObstacle, eye);
  world.draw();
  site.draw();
  for (std::size_t i = 0; i < uavs.size(); ++i) {
    if (skip_uav && *skip_uav == i) continue;
    setUniforms(program, uavs[i].matrix(), view, proj, 0, PixelClass::kUav, eye);
    uav.draw();
  }
  if (worker_set) {
    setUniforms(program, I, view, proj, 0, PixelClass::kWorker, eye);
    worker.draw();
  }
  for (std::size_t i = 0; i < bystander_count; ++i) {
    setUniforms(program, I, view, proj, 0, static_cast<PixelClass>(static_cast<int>(PixelClass::kBystander) + static_cast<int>(i)), eye);
    bystanders[i].draw();
  }
  glUseProgram(sky_program);
  Eigen::Matrix3d Kinv = Eigen::Matrix3d::Identity();
  Kinv(0, 0) = 1.0 / k.fx, Kinv(1, 1) = 1.0 / k.fy, Kinv(0, 2) = -k.cx / k.fx, Kinv(1, 2) = -k.cy / k.fy;
  const Eigen::Matrix3f ray = (cam.T_world_camera.linear() * Kinv).cast<float>();
  glUniformMatrix3fv(glGetUniformLocation(sky_program, "u_ray"), 1, GL_FALSE, ray.data());
  const Eigen::Vector3f sun = config.sun_direction_world.normalized().cast<float>();
  glUniform3fv(glGetUniformLocation(sky_program, "u_sun"), 1, sun.data());
  glBindVertexArray(sky_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

void Renderer::Impl::readBack(int width, int height, RenderedFrame& f) {
  rgba.create(height, width, CV_8UC4);
  f.depth_m.create(height, width, CV_32FC1);
  f.classes.create(height, width, CV_8UC1);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);  // RGBA: the fast path
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  glReadPixels(0, 0, width, height, GL_RED, GL_FLOAT, f.depth_m.data);
  glReadBuffer(GL_COLOR_ATTACHMENT2);
  glReadPixels(0, 0, width, height, GL_RED, GL_UNSIGNED_BYTE, f.classes.data);
  cv::cvtColor(rgba, f.rgb, cv::COLOR_RGBA2RGB);
}

common::Result<RenderedFrame> Renderer::render(const CameraView& cam, std::optional<std::size_t> skip_uav) {
  using R = common::Result<RenderedFrame>;
  const auto& k = cam.intrinsics;
  auto problems = k.validate();
  if (!estimation::CameraModel(k).isDistortionFree()) problems.push_back("camera.distortion must be zero (the render is rectified)");
  if (k.width_px > 8192 || k.height_px > 8192) problems.push_back("camera image larger than 8192 px");
  if (!cam.T_world_camera.matrix().allFinite()) problems.push_back("camera pose T_world_camera must be finite");
  if (!problems.empty()) return R::fail(problems.front());
  Impl& m = *impl_;
  if (!m.makeCurrent()) return R::fail("eglMakeCurrent failed: " + eglErrorText());
  m.ensureFramebuffer(k.width_px, k.height_px);
  m.drawScene(cam, skip_uav);
  RenderedFrame f;
  m.readBack(k.width_px, k.height_px, f);
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    std::ostringstream s;
    s << "OpenGL error 0x" << std::hex << err << " while rendering";
    return R::fail(s.str());
  }
  f.worker = m.truth(cam, f);
  for (std::size_t i = 0; i < m.bystander_count; ++i) {
    const cv::Mat mask = f.classes == static_cast<int>(PixelClass::kBystander) + static_cast<int>(i);
    BystanderTruth b;
    b.visible_pixels = cv::countNonZero(mask);
    if (b.visible_pixels > 0) b.visible_box_px = cv::boundingRect(mask);
    f.bystanders.push_back(b);
  }
  return R::ok(std::move(f));
}

}  // namespace gesture_formation::render
