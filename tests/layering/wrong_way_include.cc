// Compiled only by the Layering tests, which expect it to fail: a layer may not see the headers
// of a layer above it, and the build must say so rather than let the include through. The
// header is the test's (MOTIONDB_WRONG_WAY_HEADER, a quoted path).
#include MOTIONDB_WRONG_WAY_HEADER
