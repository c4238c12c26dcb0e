// The exit code and message a tool reports for an exception (libcommon/core/failure.h): a
// thread that cannot start is the environment (4), not a bug (5).
#include "libcommon/core/failure.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <filesystem>
#include <new>
#include <system_error>

namespace rad {
namespace {

template <class E>
Failure failureFrom(const E& e) {
  return failureOf(std::make_exception_ptr(e));
}

TEST(Failure, ThreadStartFailureIsEnvironment) {
  // What std::thread throws when pthread_create fails (RLIMIT_NPROC).
  const Failure f = failureFrom(std::system_error(EAGAIN, std::generic_category(), "thread"));
  EXPECT_EQ(f.code, ExitCode::kEnvironment);
  EXPECT_EQ(f.message.rfind("cannot start a thread: ", 0), 0u) << f.message;
  EXPECT_EQ(failureFrom(std::system_error(ENOMEM, std::system_category(), "x")).code,
            ExitCode::kEnvironment);
}

TEST(Failure, OtherExceptionsKeepTheirCodes) {
  EXPECT_EQ(failureFrom(inputError("a.gltf", "bad")).code, ExitCode::kBadInput);
  EXPECT_EQ(failureFrom(inputError("a.gltf", "bad")).message, "a.gltf: bad");
  EXPECT_EQ(failureFrom(std::bad_alloc()).code, ExitCode::kEnvironment);
  EXPECT_EQ(failureFrom(std::bad_alloc()).message, "out of memory");
  EXPECT_EQ(failureFrom(std::system_error(EINVAL, std::generic_category(), "x")).code,
            ExitCode::kInternal);
  const Failure logic = failureFrom(std::logic_error("oops"));
  EXPECT_EQ(logic.code, ExitCode::kInternal);
  EXPECT_EQ(logic.message, "internal error: oops");
  EXPECT_EQ(failureOf(std::make_exception_ptr(42)).code, ExitCode::kInternal);
  EXPECT_EQ(failureOf(nullptr).code, ExitCode::kInternal);
}

}  // namespace
}  // namespace rad
