#include "huge_pages.hpp"

#include <gtest/gtest.h>

namespace pitchlab::apps {
namespace {

// The tunable is added to what the variable holds, and a value that sets it already (the user's
// "=0" as well) is left alone: no second start-up, the user's choice stands.
TEST(HugePages, TheTunableIsAppendedUnlessTheVariableSetsItAlready) {
  EXPECT_EQ(WithHugePageMalloc(""), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(WithHugePageMalloc("glibc.malloc.arena_max=2"),
            "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
  EXPECT_EQ(WithHugePageMalloc("glibc.malloc.hugetlb=0"), "");
  EXPECT_EQ(WithHugePageMalloc("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1"), "");
}

}  // namespace
}  // namespace pitchlab::apps
