// Small real libraries for the request fuzzers: a SQLite file in a fresh temporary folder (on
// /dev/shm when there is one, where commits cost no disk flush) holding clips of the synthetic
// humanoid and a space "body", with its index resident as the server keeps it. Made once per
// process, on first use.
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

// About 20 s in three clips (two of each of three actions). Aborts (a fuzzer cannot run without
// it) when the library cannot be made, as does the next.
FuzzLibrary& TheFuzzLibrary();
// The same three actions once each with short rests, in three clips: for the space fuzzer, whose
// every input builds a space over the whole library, so that its time goes with the library's
// frames while what it checks (the request's conversion and validation) does not.
FuzzLibrary& TheSmallFuzzLibrary();

// Aborts with `what` when `status` is INTERNAL or UNKNOWN: bad input of any kind must get a
// clear error of its own kind, and an INTERNAL answer to one is a bug.
void CheckNotInternal(const absl::Status& status, const char* what);

}  // namespace motiondb::fuzz

#endif  // MOTIONDB_TESTS_FUZZ_FUZZ_LIBRARY_H_
