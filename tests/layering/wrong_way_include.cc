// Compiled only by the Layering test, which expects it to fail: the search engine may not see
// the server's headers, and the build must say so rather than let the include through.
#include "server/catalog.h"
