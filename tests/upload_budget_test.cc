// The upload budget shared by the ingests in progress: admission, bytes held across uploads,
// and what a finished upload gives back.
#include "server/upload/upload_budget.h"

#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace motiondb::server {
namespace {

using ::testing::HasSubstr;

UploadLimits Limits(int uploads, int64_t bytes) {
  UploadLimits limits;
  limits.max_uploads = uploads;
  limits.max_buffered_bytes = bytes;
  return limits;
}

TEST(UploadBudget, AdmitsUpToTheLimitAndAgainWhenOneEnds) {
  UploadBudget budget(Limits(2, 1000));
  std::optional<UploadBudget::Ticket> a(*budget.Admit());
  absl::StatusOr<UploadBudget::Ticket> b = budget.Admit();
  ASSERT_TRUE(b.ok());
  const absl::StatusOr<UploadBudget::Ticket> c = budget.Admit();
  EXPECT_EQ(c.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(c.status().message()), HasSubstr("2 uploads are in progress"));
  EXPECT_EQ(budget.uploads(), 2);
  a.reset();
  EXPECT_EQ(budget.uploads(), 1);
  EXPECT_TRUE(budget.Admit().ok());
}

TEST(UploadBudget, BytesAreBoundedAcrossUploadsAndGivenBack) {
  UploadBudget budget(Limits(4, 1000));
  std::optional<UploadBudget::Ticket> a(*budget.Admit());
  UploadBudget::Ticket b = *budget.Admit();
  ASSERT_TRUE(a->Reserve(600).ok());
  const absl::Status over = b.Reserve(401);
  EXPECT_EQ(over.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(over.message()), HasSubstr("hold 600 bytes"));
  EXPECT_THAT(std::string(over.message()), HasSubstr("at most 1000"));
  // A refused reservation counts nothing; what fits does.
  EXPECT_TRUE(b.Reserve(400).ok());
  EXPECT_EQ(budget.buffered_bytes(), 1000);
  a.reset();
  EXPECT_EQ(budget.buffered_bytes(), 400);
  EXPECT_TRUE(b.Reserve(600).ok());
  // A ticket moved from gives nothing back twice.
  UploadBudget::Ticket moved = std::move(b);
  EXPECT_EQ(budget.uploads(), 1);
  EXPECT_EQ(budget.buffered_bytes(), 1000);
}

}  // namespace
}  // namespace motiondb::server
