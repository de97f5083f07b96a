// SPDX-License-Identifier: MIT
// CBRDF_RETURN_IF_ERROR and CBRDF_ASSIGN_OR_RETURN (format/include/cbrdf/status.h): an error
// leaves the function with its code and message unchanged and runs nothing after it, a value is
// moved (never copied) into a new or an existing variable, and several uses share a scope.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>

#include "cbrdf/status.h"

namespace cbrdf {
namespace {

// Counts its copies and moves, to tell which of the two the macro does.
struct Counted {
  static inline int copies = 0;
  static inline int moves = 0;
  int value = 0;
  explicit Counted(int v) : value(v) {}
  Counted(const Counted& o) : value(o.value) { ++copies; }
  Counted(Counted&& o) noexcept : value(o.value) { ++moves; }
  Counted& operator=(const Counted& o) {
    value = o.value;
    ++copies;
    return *this;
  }
  Counted& operator=(Counted&& o) noexcept {
    value = o.value;
    ++moves;
    return *this;
  }
};

Expected<Counted> make_counted(int v) {
  if (v < 0) return error(ErrorCode::kCorrupt, "negative " + std::to_string(v));
  return Counted(v);
}

Expected<std::unique_ptr<int>> make_owned(int v) {
  if (v < 0) return error(ErrorCode::kLimit, "too few: " + std::to_string(v));
  return std::make_unique<int>(v);
}

// Into a Status-returning function; `after` records whether the code after the macro ran.
Status sum_into(int a, int b, int* sum, bool* after) {
  CBRDF_ASSIGN_OR_RETURN(auto x, make_counted(a));
  CBRDF_ASSIGN_OR_RETURN(Counted y, make_counted(b));  // a second temporary in the same scope
  *after = true;
  *sum = x.value + y.value;
  return ok_status();
}

// Into an Expected<U> of another type, and a move-only value.
Expected<int> owned_plus_one(int v) {
  CBRDF_ASSIGN_OR_RETURN(std::unique_ptr<int> p, make_owned(v));
  return *p + 1;
}

// An existing variable is assigned, not declared.
Expected<std::string> assign_existing(int v) {
  Counted c(-7);
  CBRDF_ASSIGN_OR_RETURN(c, make_counted(v));
  return std::to_string(c.value);
}

Status check_positive(int v) {
  if (v <= 0)
    return error(ErrorCode::kInvalidArgument, "must be positive, not " + std::to_string(v));
  return ok_status();
}

Status both_positive(int a, int b, bool* after) {
  CBRDF_RETURN_IF_ERROR(check_positive(a));
  CBRDF_RETURN_IF_ERROR(check_positive(b));
  *after = true;
  return ok_status();
}

TEST(StatusMacros, AssignOrReturnMovesTheValue) {
  Counted::copies = 0;
  Counted::moves = 0;
  int sum = 0;
  bool after = false;
  ASSERT_TRUE(sum_into(2, 40, &sum, &after).ok());
  EXPECT_TRUE(after);
  EXPECT_EQ(sum, 42);
  EXPECT_EQ(Counted::copies, 0);
  EXPECT_GT(Counted::moves, 0);

  Expected<int> owned = owned_plus_one(41);
  ASSERT_TRUE(owned.ok());
  EXPECT_EQ(*owned, 42);

  Counted::copies = 0;
  Expected<std::string> assigned = assign_existing(5);
  ASSERT_TRUE(assigned.ok());
  EXPECT_EQ(*assigned, "5");
  EXPECT_EQ(Counted::copies, 0);
}

TEST(StatusMacros, AssignOrReturnPassesTheErrorThroughUnchanged) {
  int sum = -1;
  bool after = false;
  const Status first = sum_into(-3, 1, &sum, &after);
  EXPECT_EQ(first.code(), ErrorCode::kCorrupt);
  EXPECT_EQ(first.message(), "negative -3");
  EXPECT_FALSE(after);
  EXPECT_EQ(sum, -1);

  const Status second = sum_into(1, -4, &sum, &after);
  EXPECT_EQ(second.code(), ErrorCode::kCorrupt);
  EXPECT_EQ(second.message(), "negative -4");
  EXPECT_FALSE(after);

  const Expected<int> owned = owned_plus_one(-2);
  ASSERT_FALSE(owned.ok());
  EXPECT_EQ(owned.status().code(), ErrorCode::kLimit);
  EXPECT_EQ(owned.status().message(), "too few: -2");

  const Expected<std::string> assigned = assign_existing(-9);
  ASSERT_FALSE(assigned.ok());
  EXPECT_EQ(assigned.status().code(), ErrorCode::kCorrupt);
  EXPECT_EQ(assigned.status().message(), "negative -9");
}

TEST(StatusMacros, ReturnIfErrorStopsAtTheFirstError) {
  bool after = false;
  EXPECT_TRUE(both_positive(1, 2, &after).ok());
  EXPECT_TRUE(after);
  after = false;
  const Status st = both_positive(3, 0, &after);
  EXPECT_EQ(st.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(st.message(), "must be positive, not 0");
  EXPECT_FALSE(after);
}

}  // namespace
}  // namespace cbrdf
