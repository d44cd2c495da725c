// A double as text with 12 significant digits, fast: the BVH writer's numbers (a 10 s range at
// 120 fps of a 31-joint skeleton is 115200 of them).
#ifndef MOTIONDB_UTIL_DECIMAL_TEXT_H_
#define MOTIONDB_UTIL_DECIMAL_TEXT_H_

namespace motiondb {

// Room for what WriteDecimal12 writes, with a margin.
inline constexpr int kMaxDecimal12Chars = 24;
// The longest text WriteDecimal12 writes: a sign, 12 digits, the point and a three-digit exponent
// ("-1.23456789012e-100"); what bounds on the size of such text count.
inline constexpr int kLongestDecimal12Text = 19;

// Writes at `out` exactly the text of std::to_chars(value, std::chars_format::general, 12):
// "-32.9847707373", "0.000125", "1e+15", "nan"; returns the end of it. Values from 1e-4 to
// below 1e12 (fixed notation) take a fast path, several times faster than libstdc++'s precision
// overload; the rest, and the few whose 12th digit lies too near a rounding tie for a double
// product to settle it, are handed to std::to_chars. `out` must have room for
// kMaxDecimal12Chars.
char* WriteDecimal12(char* out, double value);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_DECIMAL_TEXT_H_
