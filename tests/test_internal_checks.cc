// Internal checks (TUMBLE_ASSERT) are on in Debug and RelWithDebInfo, the sanitizer builds among
// them, and off in Release (physics/status.h).
#include <gtest/gtest.h>

#include <string>

#include "physics/status.h"

namespace tumble {
namespace {

#if TUMBLE_ASSERTS
constexpr bool kChecksOn = true;
#else
constexpr bool kChecksOn = false;
#endif

TEST(InternalChecks, OnExactlyInDebugAndRelWithDebInfo) {
  const std::string build_type = TUMBLE_TEST_BUILD_TYPE;
  EXPECT_EQ(kChecksOn, build_type == "Debug" || build_type == "RelWithDebInfo") << build_type;
}

TEST(InternalChecks, AFailedCheckAbortsNamingTheCondition) {
#if TUMBLE_ASSERTS
  const Result<int> refused = Status::error("no value");
  EXPECT_DEATH((void)refused.value(), "internal check failed: ok\\(\\)");
#else
  GTEST_SKIP() << "internal checks are off in this build (" << TUMBLE_TEST_BUILD_TYPE << ")";
#endif
}

}  // namespace
}  // namespace tumble
