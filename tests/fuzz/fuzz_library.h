// A small real library for the request fuzzers: a SQLite file in a fresh temporary folder (on
// /dev/shm when there is one, where commits cost no disk flush) holding about 20 s of the
// synthetic humanoid in three clips and a space "body", with its index resident as the server
// keeps it. Made once per process, on first use.
#ifndef MOTIONDB_TESTS_FUZZ_FUZZ_LIBRARY_H_
#define MOTIONDB_TESTS_FUZZ_FUZZ_LIBRARY_H_

#include <memory>
#include <string>

#include "server/catalog.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::fuzz {

struct FuzzLibrary {
  std::string path;  // the SQLite file
  std::unique_ptr<storage::Database> database;
  server::IndexRegistry registry;
  std::unique_ptr<server::Catalog> catalog;
};

// Aborts (a fuzzer cannot run without it) when the library cannot be made.
FuzzLibrary& TheFuzzLibrary();

// Aborts with `what` when `status` is INTERNAL or UNKNOWN: bad input of any kind must get a
// clear error of its own kind, and an INTERNAL answer to one is a bug.
void CheckNotInternal(const absl::Status& status, const char* what);

}  // namespace motiondb::fuzz

#endif  // MOTIONDB_TESTS_FUZZ_FUZZ_LIBRARY_H_
