// The one way to see OpenGL in this repo. There is no loader (GLEW/glad): Mesa's libOSMesa
// exports the GL entry points itself (nm -D libOSMesa.so lists ~1300 gl* symbols), so the
// prototypes from <GL/glext.h> link directly. A few GL 4.5 functions are NOT exported
// (glClipControl among them, Mesa 22.3): fetch those with glProcAddress() from gl_context.h;
// a link error naming a gl* symbol means exactly that.
//
// Include this header before any other GL header, in .cpp files only.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>
