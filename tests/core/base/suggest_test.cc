#include "core/base/suggest.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace armfault {
namespace {

TEST(NearestId, FindsTheTypoAmongIdsThatShareTheLongestPrefix) {
  const std::vector<std::string> ids = {"exp1/healthy/0", "exp1/healthy/1", "exp1/kt_degradation#0/kt_factor=0.6/j3/r0",
                                        "exp1/kt_degradation#0/kt_factor=0.8/j3/r0", "p2p/healthy/0"};
  EXPECT_EQ(NearestId("exp1/healty/1", ids), "exp1/healthy/1");
  EXPECT_EQ(NearestId("exp1/kt_degradation#0/kt_factor=0.7/j3/r0", ids), "exp1/kt_degradation#0/kt_factor=0.6/j3/r0");
  EXPECT_EQ(NearestId("exp1/kt_degradation#0/kt_factor=0.8/j3/r1", ids), "exp1/kt_degradation#0/kt_factor=0.8/j3/r0");
  EXPECT_EQ(NearestId("p2p/healthy/7", ids), "p2p/healthy/0");
  // However far, one of the ids; none when there are none.
  EXPECT_EQ(NearestId("zzz", ids), "p2p/healthy/0");  // the fewest edits: the shortest
  EXPECT_EQ(NearestId("exp1/healthy/0", {}), "");
}

}  // namespace
}  // namespace armfault
