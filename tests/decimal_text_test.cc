// WriteDecimal12 writes, byte for byte, what std::to_chars(value, general, 12) writes.
#include "util/decimal_text.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace motiondb {
namespace {

std::string Expected(double value) {
  char buffer[32];
  return std::string(
      buffer,
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 12).ptr);
}

std::string Written(double value) {
  char buffer[kMaxDecimal12Chars];
  return std::string(buffer, WriteDecimal12(buffer, value));
}

TEST(DecimalText, ChosenValues) {
  EXPECT_EQ(Written(-32.98477073732698), "-32.9847707373");
  EXPECT_EQ(Written(0.000125), "0.000125");
  EXPECT_EQ(Written(90), "90");
  EXPECT_EQ(Written(1e15), "1e+15");
  const double kInf = std::numeric_limits<double>::infinity();
  const double values[] = {0.0,
                           -0.0,
                           1.0,
                           -1.0,
                           0.1,
                           10.0,
                           1e-4,
                           9.99999999999951e-5,
                           0.00012,
                           1e-5,
                           123.5,
                           0.5,
                           999999999999.4,
                           999999999999.5,
                           1e12,
                           1e11,
                           123456789012.5,
                           1234567890.125,
                           99999999999.95,
                           0.000999999999999951,
                           kInf,
                           -kInf,
                           std::nan(""),
                           -1.23456789012345e-100,
                           -std::numeric_limits<double>::denorm_min(),
                           -std::numeric_limits<double>::max()};
  for (const double value : values) {
    EXPECT_EQ(Written(value), Expected(value)) << value;
  }
}

// Every decade of the fixed notation and beyond it, values next to powers of ten and to the
// 12th digit's rounding ties, values with 4 decimals as capture files have, and float32 values
// as the database stores.
TEST(DecimalText, RandomValuesMatchToChars) {
  std::mt19937_64 generator(12);
  std::uniform_real_distribution<double> decade(-7, 14);
  std::normal_distribution<double> angle(0, 60);
  std::uniform_int_distribution<int64_t> digits(100000000000, 999999999999);
  int checked = 0;
  const auto check = [&](double value) {
    ASSERT_EQ(Written(value), Expected(value)) << std::hexfloat << value;
    ++checked;
  };
  for (int n = 0; n < 200000; ++n) {
    const double sign = generator() % 2 ? -1 : 1;
    check(sign * std::pow(10.0, decade(generator)));
    check(angle(generator));
    const double power = std::pow(10.0, std::round(decade(generator)));
    check(std::nextafter(power, 0.0));
    check(std::nextafter(power, HUGE_VAL));
    // x.5 in the 13th digit: as near a tie as a double gets.
    const double exponent = std::round(decade(generator));
    check(sign * (digits(generator) + 0.5) * std::pow(10.0, exponent - 11));
    check(std::round(angle(generator) * 1e4) / 1e4);
    check(static_cast<float>(angle(generator)));
  }
  EXPECT_EQ(checked, 7 * 200000);
}

}  // namespace
}  // namespace motiondb
