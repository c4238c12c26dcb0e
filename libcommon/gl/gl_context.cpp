// OSMesa context management. OSMesa API: Mesa's include/GL/osmesa.h.
#include "libcommon/gl/gl_api.h"
// gl_api.h first: it must define GL_GLEXT_PROTOTYPES before any GL header.
#include "libcommon/gl/gl_context.h"

#include <GL/osmesa.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "libcommon/core/error.h"

namespace rad {
namespace {

Error environmentError(const std::string& what) {
  return Error(ExitCode::kEnvironment, "osmesa", what);
}

const char* errorName(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    case GL_STACK_OVERFLOW:
      return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW:
      return "GL_STACK_UNDERFLOW";
    default:
      return "unknown GL error";
  }
}

std::string glString(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
}

GLuint compileShader(const std::string& name, GLenum type, const std::string& source) {
  GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::max(length, 1), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw Error(ExitCode::kInternal, "glsl " + name,
                std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                    " shader does not compile: " + log.c_str());
  }
  return shader;
}

// Core profile 4.5: FBOs, integer targets, GL_DEPTH_COMPONENT32F and glClipControl.
// No depth/stencil/accum in the dummy default framebuffer: all rendering goes to FBOs.
OSMesaContext createCoreContext() {
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         4,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         5,
                         0};
  return OSMesaCreateContextAttribs(attribs, nullptr);
}

// What the user set that chooses Mesa's driver, for the messages: " with GALLIUM_DRIVER=x" or "".
std::string driverChoice() {
  const char* driver = std::getenv("GALLIUM_DRIVER");
  return driver ? std::string(" with GALLIUM_DRIVER=") + driver : std::string();
}

// The environment variable that makes a copy of this program the probe's child (below).
constexpr const char* kProbeChildVariable = "RAD_GL_PROBE_CHILD";

// The probe's child, before main: a fresh copy of this program (probeContextInChild spawns
// /proc/self/exe with kProbeChildVariable=1) creates a context and exits, 0 when it worked.
// Its static initialisers run first, none of which starts a thread or takes a lock a context
// needs.
[[maybe_unused]] const bool kProbeChild = [] {
  const char* value = std::getenv(kProbeChildVariable);
  if (!value || std::strcmp(value, "1") != 0) return false;
  const rlimit noCore{0, 0};  // a crash here is expected, not a core file to leave behind
  setrlimit(RLIMIT_CORE, &noCore);
  _exit(createCoreContext() ? 0 : 1);
}();

// How creating a context went in a child process: "" when it worked, else why not. Mesa 22.3
// dereferences a null screen when GALLIUM_DRIVER names a driver it cannot load (nonexistent,
// or zink without Vulkan): a SIGSEGV inside OSMesaCreateContextAttribs that no check in this
// process can catch. The child (its output silenced: Mesa's own complaints are several lines)
// takes the fall; the screen is made once per process, so one probe serves every context.
// The child is a new copy of the program (posix_spawn), not a fork: the first context is often made
// by a worker thread, and a fork copies the locks other threads hold at that moment; Mesa's atexit
// registration in a forked child can wait forever on glibc's exit-function lock, and rad-movies
// with it.
std::string probeContextInChild() {
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, kProbeChildVariable, std::strlen(kProbeChildVariable)) != 0)
      env.emplace_back(*e);
  env.push_back(std::string(kProbeChildVariable) + "=1");
  std::vector<char*> envp;
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  char name[] = "rad-gl-probe";
  char* argv[] = {name, nullptr};
  posix_spawn_file_actions_t silence;
  posix_spawn_file_actions_init(&silence);
  posix_spawn_file_actions_addopen(&silence, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&silence, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, "/proc/self/exe", &silence, nullptr, argv, envp.data());
  posix_spawn_file_actions_destroy(&silence);
  if (spawned != 0) return "";  // cannot probe (no /proc, no memory): try in this process
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return "";
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  if (WIFSIGNALED(status))
    return std::string("Mesa crashed (") + strsignal(WTERMSIG(status)) +
           ") creating an OpenGL context" + driverChoice();
  return "cannot create an OpenGL 4.5 core context" + driverChoice();
}

// Address space a context needs beyond what the process has mapped when it is made: llvmpipe
// starts a rasteriser thread per core (each with its stack) and LLVM's JIT maps its code and
// heaps when the first shaders compile. Mesa does not fail cleanly when an allocation fails:
// under `ulimit -v` the stages died of SIGSEGV in the shader compile or of LLVM's abort, after
// a context had been made. So under an address-space limit a context is refused up front
// (exit 4) unless this much is left: the base (LLVM, the shaders) for the process's first
// context only, the per-core part (the rasteriser threads) for each. Without a limit nothing
// is checked.
constexpr size_t kMiB = size_t(1) << 20;
constexpr size_t kGlAddressSpaceBase = 512 * kMiB;
constexpr size_t kGlAddressSpacePerCore = 64 * kMiB;

// "" when RLIMIT_AS leaves room for a context, else why not (one line).
std::string addressSpaceShortage() {
  static std::atomic<bool> first{true};
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return "";
  size_t pages = 0;
  if (FILE* statm = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(statm, "%zu", &pages) != 1) pages = 0;
    std::fclose(statm);
  }
  const size_t mapped = pages * size_t(sysconf(_SC_PAGESIZE));
  const long cores = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
  const size_t need =
      (first.exchange(false) ? kGlAddressSpaceBase : 0) + size_t(cores) * kGlAddressSpacePerCore;
  const size_t cap = size_t(limit.rlim_cur);
  if (mapped < cap && cap - mapped >= need) return "";
  const size_t left = mapped < cap ? cap - mapped : 0;
  return "the address-space limit (ulimit -v " + std::to_string(cap / 1024) + ") leaves " +
         std::to_string(left / kMiB) + " MiB; an OpenGL context (Mesa llvmpipe, " +
         std::to_string(cores) + " cores) needs " + std::to_string(need / kMiB) +
         " MiB more: raise the limit";
}

// The probe's verdict, taken once per process before its first context.
const std::string& contextProbe() {
  static const std::string verdict = probeContextInChild();
  return verdict;
}

}  // namespace

GlContext::GlContext() {
  const std::string remedy = std::getenv("GALLIUM_DRIVER")
                                 ? "; unset GALLIUM_DRIVER or set it to llvmpipe"
                                 : " (OSMesaCreateContextAttribs failed; is libosmesa6 with "
                                   "llvmpipe installed?)";
  if (const std::string shortage = addressSpaceShortage(); !shortage.empty())
    throw environmentError(shortage);
  if (const std::string& failed = contextProbe(); !failed.empty())
    throw environmentError(failed + remedy);
  OSMesaContext ctx = createCoreContext();
  if (!ctx)
    throw environmentError("cannot create an OpenGL 4.5 core context" + driverChoice() + remedy);
  context_ = ctx;
  dummy_.assign(4, 0);
  if (!OSMesaMakeCurrent(ctx, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    OSMesaDestroyContext(ctx);
    context_ = nullptr;
    throw environmentError("cannot make the OpenGL context current (OSMesaMakeCurrent failed)");
  }
  // GL's default for pixel rows is fine for 4-byte texels, but make packing explicit.
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
}

GlContext::~GlContext() {
  if (context_) {
    if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(context_))
      OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
  }
}

void GlContext::makeCurrent() {
  auto ctx = static_cast<OSMesaContext>(context_);
  if (OSMesaGetCurrentContext() == ctx) return;
  if (!OSMesaMakeCurrent(ctx, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1))
    throw environmentError("cannot make the OpenGL context current (OSMesaMakeCurrent failed)");
}

std::string GlContext::renderer() const {
  return glString(GL_RENDERER);
}
std::string GlContext::version() const {
  return glString(GL_VERSION);
}

void* glProcAddress(const char* name) {
  void* p = reinterpret_cast<void*>(OSMesaGetProcAddress(name));
  if (!p) throw environmentError(std::string("the GL driver lacks ") + name);
  return p;
}

unsigned compileProgram(const std::string& name, const std::string& vertexSource,
                        const std::string& fragmentSource) {
  GLuint vs = compileShader(name, GL_VERTEX_SHADER, vertexSource);
  GLuint fs = 0;
  try {
    fs = compileShader(name, GL_FRAGMENT_SHADER, fragmentSource);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  // The program keeps the compiled code; the shader objects can go now.
  glDetachShader(program, vs);
  glDetachShader(program, fs);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::max(length, 1), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    glDeleteProgram(program);
    throw Error(ExitCode::kInternal, "glsl " + name, std::string("does not link: ") + log.c_str());
  }
  return program;
}

void checkGlError(const std::string& where) {
  std::string names;
  bool outOfMemory = false;
  // glGetError returns one flag per call; bounded loop in case a broken driver never clears.
  for (int i = 0; i < 16; ++i) {
    GLenum e = glGetError();
    if (e == GL_NO_ERROR) break;
    outOfMemory = outOfMemory || e == GL_OUT_OF_MEMORY;
    names += names.empty() ? errorName(e) : std::string(", ") + errorName(e);
  }
  if (names.empty()) return;
  throw Error(outOfMemory ? ExitCode::kEnvironment : ExitCode::kInternal, "gl: " + where, names);
}

void configureReversedZ() {
  using ClipControlFn = void(APIENTRY*)(GLenum, GLenum);
  // Not exported by libOSMesa (see gl_api.h); core since GL 4.5.
  static const auto clipControl = reinterpret_cast<ClipControlFn>(glProcAddress("glClipControl"));
  clipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glDepthFunc(GL_GREATER);
  glClearDepthf(0.0f);
}

}  // namespace rad
