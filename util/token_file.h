// Bearer tokens kept in files (--auth-token-file, --token-file, secrets mounted in containers).
#ifndef MOTIONDB_UTIL_TOKEN_FILE_H_
#define MOTIONDB_UTIL_TOKEN_FILE_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb {

// The file's contents without surrounding whitespace. INVALID_ARGUMENT naming the path when
// the token is empty or not printable ASCII without spaces (it travels in an HTTP/2 header
// value); the file's read errors otherwise. Files over 1 MiB are refused as a wrong path.
absl::StatusOr<std::string> ReadTokenFile(const std::string& path);

// What a token lets its holder do; each scope holds the ones below it.
enum class TokenScope {
  kRead = 1,   // search, list, export, curves: what the web page reads
  kWrite = 2,  // and ingest, labels, jobs, spaces, edits
  kAdmin = 3,  // and deletes, backups, metrics
  // And what a cluster's router asks of its shard nodes (motiondb.shard.v1), having checked its
  // own caller: held only by the cluster's own token (--cluster-token-file), never by a line of
  // a token file.
  kCluster = 4,
};

// "read", "write", "admin", "cluster".
absl::string_view TokenScopeName(TokenScope scope);

struct ScopedToken {
  TokenScope scope = TokenScope::kAdmin;
  std::string token;
};

// The server's token file (--auth-token-file): a line a token, "SCOPE TOKEN" with SCOPE one of
// read, write, admin; blank lines and lines starting with '#' are skipped. A file holding one
// bare token (no scope) gives it every right, as files did before scopes. INVALID_ARGUMENT
// naming the path and line for an unknown scope, a token that is not printable ASCII without
// spaces, a token given twice, or no token at all.
absl::StatusOr<std::vector<ScopedToken>> ReadScopedTokenFile(const std::string& path);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_TOKEN_FILE_H_
