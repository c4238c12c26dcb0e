// Temporary files removed when the process is interrupted (issue 54): AtomicFile registers its
// temporary while it may exist, and a SIGINT, SIGTERM or SIGHUP removes every registered one
// before the process dies of that signal. Without it an interrupted write left its hidden
// `.name.tmp.<pid>.<n>.ext` behind (SIGKILL still can: nothing runs then).
#pragma once

#include <string>

namespace rad {

// At most this many temporaries are registered at once (one per writing thread is the use;
// --threads is at most 1024). Beyond it a temporary is not registered, and an interrupt can
// leave it behind as SIGKILL does.
constexpr int kMaxRegisteredTempFiles = 4096;

// Registers `path` (copied) for removal on SIGINT, SIGTERM and SIGHUP; returns its slot for
// unregisterTempFile, or -1 when the registry is full. The first call installs the handlers,
// except for a signal whose disposition is SIG_IGN (a background job's SIGINT, nohup's
// SIGHUP), which stays ignored, and one that already has a handler. The handler unlinks every
// registered path (async-signal-safe: unlink only), restores the default action and raises
// the signal again, so the exit status stays "killed by SIGTERM" (128 + 15 in a shell).
// Thread-safe.
int registerTempFile(const std::string& path);

// Forgets slot `slot` (from registerTempFile; -1 is ignored): call it once the temporary is
// renamed into place or removed. If the signal handler is removing that slot's file right
// now, waits for the process to end.
void unregisterTempFile(int slot);

}  // namespace rad
