#include "libcommon/core/failure.h"

#include <cerrno>
#include <new>
#include <system_error>

namespace rad {

namespace {
bool is(const std::error_code& code, std::errc what) {
  return code.default_error_condition() == what;
}
}  // namespace

Failure failureOf(std::exception_ptr error) {
  if (!error) return {ExitCode::kInternal, "internal error: no exception"};
  try {
    std::rethrow_exception(error);
  } catch (const Error& e) {
    return {e.code(), e.what()};
  } catch (const std::bad_alloc&) {
    return {ExitCode::kEnvironment, "out of memory"};
  } catch (const std::system_error& e) {
    // pthread_create's EAGAIN: RLIMIT_NPROC or the kernel's thread limit.
    if (is(e.code(), std::errc::resource_unavailable_try_again))
      return {ExitCode::kEnvironment, std::string("cannot start a thread: ") + e.what() +
                                          " (lower --threads, or raise ulimit -u)"};
    if (is(e.code(), std::errc::not_enough_memory))
      return {ExitCode::kEnvironment, std::string("out of memory: ") + e.what()};
    return {ExitCode::kInternal, std::string("internal error: ") + e.what()};
  } catch (const std::exception& e) {
    return {ExitCode::kInternal, std::string("internal error: ") + e.what()};
  } catch (...) {
    return {ExitCode::kInternal, "internal error: unknown exception"};
  }
}

}  // namespace rad
