// A double as text with 12 significant digits, fast: the BVH writer's numbers (a 10 s range at
// 120 fps of a 31-joint skeleton is 115200 of them).
#ifndef MOTIONDB_UTIL_DECIMAL_TEXT_H_
#define MOTIONDB_UTIL_DECIMAL_TEXT_H_

namespace motiondb {

// The most characters WriteDecimal12 writes ("-1.23456789012e-100" is 19).
inline constexpr int kMaxDecimal12Chars = 24;

// Writes at `out` exactly the text of std::to_chars(value, std::chars_format::general, 12):
// "-32.9847707373", "0.000125", "1e+15", "nan"; returns the end of it. Values from 1e-4 to
// below 1e12 (fixed notation) take a fast path, several times faster than libstdc++'s precision
// overload; the rest, and the few whose 12th digit lies too near a rounding tie for a double
// product to settle it, are handed to std::to_chars. `out` must have room for
// kMaxDecimal12Chars.
char* WriteDecimal12(char* out, double value);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_DECIMAL_TEXT_H_
