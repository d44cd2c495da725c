#include "util/decimal_text.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace motiondb {
namespace {

constexpr int kDigits = 12;

// 10^k for k in 0..15, each exact in a double (every power up to 10^22 is).
constexpr double kPowersOfTen[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                   1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
// 10^x for x in -4..12, index x + 4; the negative ones are the nearest doubles.
constexpr double kDecades[] = {1e-4, 1e-3, 1e-2, 1e-1, 1e0, 1e1,  1e2,  1e3, 1e4,
                               1e5,  1e6,  1e7,  1e8,  1e9, 1e10, 1e11, 1e12};

constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

char* WriteByToChars(char* out, double value) {
  return std::to_chars(out, out + kMaxDecimal12Chars, value, std::chars_format::general, kDigits)
      .ptr;
}

// The 6 digits of v < 10^6, leading zeros included.
void WriteSixDigits(char* out, uint32_t v) {
  const uint32_t high = v / 10000, low = v % 10000;
  std::memcpy(out, kDigitPairs + 2 * high, 2);
  std::memcpy(out + 2, kDigitPairs + 2 * (low / 100), 2);
  std::memcpy(out + 4, kDigitPairs + 2 * (low % 100), 2);
}

}  // namespace

char* WriteDecimal12(char* out, double value) {
  const double a = std::fabs(value);
  // Zero, a quarter of a BVH's numbers (the angles of joints that never turn): "0" or "-0".
  if (a == 0) {
    char* p = out;
    if (std::signbit(value)) *p++ = '-';
    *p++ = '0';
    return p;
  }
  // %g's fixed notation: the rounded value's decimal exponent x in -4..11.
  if (!(a >= 1e-4 && a < 1e12)) return WriteByToChars(out, value);
  // 2^e <= a < 2^(e + 1) puts x at floor(e log10 2) (1233 / 4096 = 0.30103) or one more.
  const int e = static_cast<int>(std::bit_cast<uint64_t>(a) >> 52) - 1023;
  int x = std::max(-4, (e * 1233) >> 12);
  if (x < 11 && a >= kDecades[x + 5]) ++x;
  // The 12 digits are a x 10^(11 - x) rounded to an integer. The product is one rounding away
  // from exact: below 10^12 < 2^40, less than 2^-13 off. So its integer part and whether its
  // fraction is above or below 1/2 are the exact product's, unless that fraction lies within
  // 2^-12 of 1/2 (a tie, or too near one to tell), which std::to_chars settles exactly. Neither
  // is an x one too small (the product reaches 10^12) or too large (it stays under 10^11, or is
  // rounded to 10^11 exactly, which then is right: a is 10^x to 12 digits).
  const double scaled = a * kPowersOfTen[kDigits - 1 - x];
  const double whole = static_cast<double>(static_cast<uint64_t>(scaled));
  const double fraction = scaled - whole;
  if (!(scaled >= 1e11 && whole < 999999999999.0) || std::fabs(fraction - 0.5) < 0x1p-12) {
    return WriteByToChars(out, value);
  }
  const uint64_t rounded = static_cast<uint64_t>(whole) + (fraction > 0.5 ? 1 : 0);
  char digits[kDigits];
  WriteSixDigits(digits, static_cast<uint32_t>(rounded / 1000000));
  WriteSixDigits(digits + 6, static_cast<uint32_t>(rounded % 1000000));
  // %g drops the fraction's trailing zeros, and the point when nothing follows it.
  const int point = x + 1;  // digits before the point; none (and -point zeros after it) if <= 0
  int end = kDigits;
  while (end > std::max(point, 0) && digits[end - 1] == '0') --end;
  char* p = out;
  if (value < 0) *p++ = '-';
  if (point > 0) {
    std::memcpy(p, digits, point);
    p += point;
    if (end > point) {
      *p++ = '.';
      std::memcpy(p, digits + point, end - point);
      p += end - point;
    }
  } else {
    std::memcpy(p, "0.0000", 2 - point);  // "0." and -point zeros, at most 4
    p += 2 - point;
    std::memcpy(p, digits, end);
    p += end;
  }
  return p;
}

}  // namespace motiondb
