// The memory budget: sizes as a user writes them, the default, the check.
#include "core/memory_budget.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace throng {
namespace {

TEST(MemoryBudget, SizesAsAUserWritesThem) {
  EXPECT_EQ(parse_memory_size("2000000", "--max-memory"), 2000000u);
  EXPECT_EQ(parse_memory_size("512M", "--max-memory"), 512ull << 20);
  EXPECT_EQ(parse_memory_size("8G", "--max-memory"), 8ull << 30);
  EXPECT_EQ(parse_memory_size("1.5GiB", "--max-memory"), 3ull << 29);
  EXPECT_EQ(parse_memory_size("2gb", "--max-memory"), 2ull << 30);
  EXPECT_EQ(parse_memory_size("4k", "--max-memory"), 4096u);
  for (const char* bad : {"", "G", "8X", "-1G", "0", "nanG", "1e30T", "8 G"}) {
    try {
      parse_memory_size(bad, "--max-memory");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_EQ(e.location().field, "--max-memory") << bad;
    }
  }
}

TEST(MemoryBudget, DefaultIsMostOfPhysicalMemoryAndAChecksNamesTheFigure) {
  set_memory_budget(0);
  const std::uint64_t physical = physical_memory_bytes();
  ASSERT_GT(physical, 0u);
  EXPECT_NEAR(static_cast<double>(memory_budget()), 0.8 * static_cast<double>(physical), 1.0);
  set_memory_budget(1ull << 30);
  EXPECT_NO_THROW(check_memory_budget(1e9, "a billion bytes", "--agents"));
  try {
    check_memory_budget(3.0 * (1ull << 30), "1000 agents", "--agents");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "--agents");
    const std::string m = e.message();
    EXPECT_NE(m.find("about 3 GiB for 1000 agents exceeds the memory budget of 1 GiB (--max-memory)"),
              std::string::npos)
        << m;
  }
  set_memory_budget(0);
  EXPECT_EQ(format_bytes(1536), "1.5 KiB");
  EXPECT_EQ(format_bytes(12), "12 bytes");
}

}  // namespace
}  // namespace throng
