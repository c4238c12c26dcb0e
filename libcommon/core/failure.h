// What a tool reports for an exception that reached its main: the exit code of the one table
// (error.h) and the message after `rad-tool: `. runTool (tools/common/tool_main.h) prints it;
// kept here, without CLI or I/O, so the mapping is unit-tested.
#pragma once

#include <exception>
#include <string>

#include "libcommon/core/error.h"

namespace rad {

struct Failure {
  ExitCode code = ExitCode::kInternal;
  std::string message;  // may span lines (library messages); the caller makes it one
};

// rad::Error: its code and text. std::bad_alloc: kEnvironment, "out of memory".
// std::system_error with EAGAIN (std::thread and TBB failing to start a thread at RLIMIT_NPROC
// or the kernel's thread limit): kEnvironment, "cannot start a thread: ..."; with ENOMEM:
// kEnvironment, "out of memory: ..." (the machine's limits, not a bug). Any other exception:
// kInternal, "internal error: what()". A null pointer is kInternal too.
Failure failureOf(std::exception_ptr error);

}  // namespace rad
