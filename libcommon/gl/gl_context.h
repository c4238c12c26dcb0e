// Off-screen OpenGL 4.5 core contexts over OSMesa (Mesa llvmpipe), plus small GL helpers.
//
// Threading: an OSMesa context is current on one thread at a time. A GlContext is made
// current on the thread that constructs it; call makeCurrent() before using it on another
// thread (never from two threads at once). One context per thread is the intended use; any
// number of GlContexts may exist, and every user calls makeCurrent() before its GL calls.
// llvmpipe rasterises with its own worker threads (LP_NUM_THREADS) and its results do not
// depend on their number.
//
// The default framebuffer is a 1x1 dummy: render into FBOs.
#pragma once

#include <string>
#include <vector>

namespace rad {

class GlContext {
 public:
  // Creates an OpenGL 4.5 core context and makes it current. Throws
  // rad::Error(ExitCode::kEnvironment, "osmesa", ...) when none can be made.
  GlContext();
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Makes this context current on the calling thread (cheap when it already is).
  void makeCurrent();
  // GL_RENDERER / GL_VERSION strings, e.g. for provenance and messages.
  std::string renderer() const;
  std::string version() const;

 private:
  void* context_ = nullptr;  // OSMesaContext
  std::vector<unsigned char> dummy_;
};

// Address of a GL function the library does not export (e.g. "glClipControl"); throws
// kEnvironment if the driver lacks it. A context should exist.
void* glProcAddress(const char* name);

// Compiles and links a program from GLSL sources; throws rad::Error(kInternal, "glsl NAME",
// ...) with the compiler's or linker's info log. Returns the GL program name.
unsigned compileProgram(const std::string& name, const std::string& vertexSource,
                        const std::string& fragmentSource);

// Throws when glGetError() reports anything (all pending errors are drained and listed):
// GL_OUT_OF_MEMORY gives kEnvironment, anything else kInternal (a bug). `where` names the
// step, e.g. "item buffer: readback".
void checkGlError(const std::string& where);

// Sets up reversed-Z depth for reversedZProjectionMatrix() (camera_projection.h):
// glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), glDepthFunc(GL_GREATER), clear depth 0.
// Pair it with a GL_DEPTH_COMPONENT32F depth attachment.
void configureReversedZ();

}  // namespace rad
