#include "envs/kuka/kuka_renderer.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include <GL/osmesa.h>

#include "common/check.h"

namespace rl::envs::kuka {
namespace {

// Lighting of PyBullet's TinyRenderer (spec 4.9): light direction (-50, 30, 100) in the world
// (z up), ambient 0.6, diffuse 0.35. Its specular term (0.05) is left out.
constexpr GLfloat kLightDirection[4] = {-50, 30, 100, 0};
constexpr GLfloat kAmbient[4] = {0.6f, 0.6f, 0.6f, 1};
constexpr GLfloat kDiffuse[4] = {0.35f, 0.35f, 0.35f, 1};
constexpr GLfloat kNone[4] = {0, 0, 0, 1};
constexpr int kMaxSize = 4096;

// Looks up one GL entry point of OSMesa.
template <typename F>
void Load(F*& function, const char* name) {
  function = reinterpret_cast<F*>(OSMesaGetProcAddress(name));
  if (function == nullptr) {
    throw std::runtime_error(std::string("KukaRenderer: OSMesa lacks ") + name);
  }
}

}  // namespace

// The context and the fixed-function GL 1.x entry points the renderer uses.
struct KukaRenderer::Gl {
  OSMesaContext context = nullptr;
  int width = 0;  // Size of the buffer the context was last made current with.
  int height = 0;
  decltype(&::glViewport) Viewport = nullptr;
  decltype(&::glClearColor) ClearColor = nullptr;
  decltype(&::glClear) Clear = nullptr;
  decltype(&::glEnable) Enable = nullptr;
  decltype(&::glMatrixMode) MatrixMode = nullptr;
  decltype(&::glLoadMatrixd) LoadMatrixd = nullptr;
  decltype(&::glMultMatrixd) MultMatrixd = nullptr;
  decltype(&::glPushMatrix) PushMatrix = nullptr;
  decltype(&::glPopMatrix) PopMatrix = nullptr;
  decltype(&::glLightfv) Lightfv = nullptr;
  decltype(&::glLightModelfv) LightModelfv = nullptr;
  decltype(&::glColorMaterial) ColorMaterial = nullptr;
  decltype(&::glColor3f) Color3f = nullptr;
  decltype(&::glShadeModel) ShadeModel = nullptr;
  decltype(&::glCullFace) CullFace = nullptr;
  decltype(&::glEnableClientState) EnableClientState = nullptr;
  decltype(&::glVertexPointer) VertexPointer = nullptr;
  decltype(&::glNormalPointer) NormalPointer = nullptr;
  decltype(&::glDrawArrays) DrawArrays = nullptr;
  decltype(&::glFinish) Finish = nullptr;

  Gl() = default;
  Gl(const Gl&) = delete;
  Gl& operator=(const Gl&) = delete;
  ~Gl() {
    if (context != nullptr) OSMesaDestroyContext(context);
  }
};

KukaRenderer::KukaRenderer() : gl_(std::make_unique<Gl>()) {
  // One llvmpipe thread per process unless the user chose otherwise (see the header).
  setenv("LP_NUM_THREADS", "1", /*overwrite=*/0);
  gl_->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (gl_->context == nullptr)
    throw std::runtime_error("KukaRenderer: OSMesaCreateContextExt failed");
  Gl& g = *gl_;
  Load(g.Viewport, "glViewport");
  Load(g.ClearColor, "glClearColor");
  Load(g.Clear, "glClear");
  Load(g.Enable, "glEnable");
  Load(g.MatrixMode, "glMatrixMode");
  Load(g.LoadMatrixd, "glLoadMatrixd");
  Load(g.MultMatrixd, "glMultMatrixd");
  Load(g.PushMatrix, "glPushMatrix");
  Load(g.PopMatrix, "glPopMatrix");
  Load(g.Lightfv, "glLightfv");
  Load(g.LightModelfv, "glLightModelfv");
  Load(g.ColorMaterial, "glColorMaterial");
  Load(g.Color3f, "glColor3f");
  Load(g.ShadeModel, "glShadeModel");
  Load(g.CullFace, "glCullFace");
  Load(g.EnableClientState, "glEnableClientState");
  Load(g.VertexPointer, "glVertexPointer");
  Load(g.NormalPointer, "glNormalPointer");
  Load(g.DrawArrays, "glDrawArrays");
  Load(g.Finish, "glFinish");
}

KukaRenderer::~KukaRenderer() = default;

void KukaRenderer::Render(const CameraParams& camera, std::span<const DrawItem> items, int width,
                          int height, std::vector<uint8_t>* rgb) {
  RL_CHECK(rgb != nullptr) << "Render needs an output buffer";
  if (width < 1 || height < 1 || width > kMaxSize || height > kMaxSize) {
    throw std::invalid_argument("KukaRenderer::Render: size must be in [1, 4096], got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  Gl& g = *gl_;
  // Bind the context to a buffer of this size on this thread.
  rgba_.resize(static_cast<std::size_t>(width) * height * 4);
  if (OSMesaMakeCurrent(g.context, rgba_.data(), GL_UNSIGNED_BYTE, width, height) == GL_FALSE) {
    throw std::runtime_error("KukaRenderer: OSMesaMakeCurrent failed");
  }
  g.width = width;
  g.height = height;

  // State: depth test, back faces culled, flat shading, one directional light, colours as
  // ambient and diffuse material, normals renormalised (the unit primitives are scaled).
  g.Viewport(0, 0, width, height);
  g.ClearColor(1, 1, 1, 1);
  g.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  g.Enable(GL_DEPTH_TEST);
  g.Enable(GL_CULL_FACE);
  g.CullFace(GL_BACK);
  g.ShadeModel(GL_FLAT);
  g.Enable(GL_NORMALIZE);
  g.Enable(GL_LIGHTING);
  g.Enable(GL_LIGHT0);
  g.Enable(GL_COLOR_MATERIAL);
  g.ColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
  g.LightModelfv(GL_LIGHT_MODEL_AMBIENT, kNone);
  g.Lightfv(GL_LIGHT0, GL_AMBIENT, kAmbient);
  g.Lightfv(GL_LIGHT0, GL_DIFFUSE, kDiffuse);
  g.Lightfv(GL_LIGHT0, GL_SPECULAR, kNone);
  g.EnableClientState(GL_VERTEX_ARRAY);
  g.EnableClientState(GL_NORMAL_ARRAY);

  // Camera (Eigen matrices are column-major, as OpenGL expects), then the light in world
  // coordinates.
  const Eigen::Matrix4d projection = ProjectionMatrix(camera, static_cast<double>(width) / height);
  const Eigen::Matrix4d view = ViewMatrix(camera);
  g.MatrixMode(GL_PROJECTION);
  g.LoadMatrixd(projection.data());
  g.MatrixMode(GL_MODELVIEW);
  g.LoadMatrixd(view.data());
  g.Lightfv(GL_LIGHT0, GL_POSITION, kLightDirection);

  for (const DrawItem& item : items) {
    RL_CHECK(item.mesh != nullptr) << "DrawItem without a mesh";
    if (item.mesh->num_vertices() == 0) continue;
    g.PushMatrix();
    g.MultMatrixd(item.transform.matrix().data());
    g.Color3f(item.color[0], item.color[1], item.color[2]);
    g.VertexPointer(3, GL_FLOAT, 0, item.mesh->positions.data());
    g.NormalPointer(GL_FLOAT, 0, item.mesh->normals.data());
    g.DrawArrays(GL_TRIANGLES, 0, item.mesh->num_vertices());
    g.PopMatrix();
  }
  g.Finish();

  // OSMesa's rows run bottom-up; the output runs top-down, RGB.
  rgb->resize(static_cast<std::size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    const uint8_t* src = rgba_.data() + static_cast<std::size_t>(height - 1 - y) * width * 4;
    uint8_t* dst = rgb->data() + static_cast<std::size_t>(y) * width * 3;
    for (int x = 0; x < width; ++x) {
      dst[3 * x] = src[4 * x];
      dst[3 * x + 1] = src[4 * x + 1];
      dst[3 * x + 2] = src[4 * x + 2];
    }
  }
}

}  // namespace rl::envs::kuka
