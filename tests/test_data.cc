#include "tests/test_data.h"

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

namespace motiondb::testing {
namespace {

std::optional<std::filesystem::path> ExistingDir(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return path;
  return std::nullopt;
}

}  // namespace

std::optional<std::filesystem::path> AssimpBvhDir() { return ExistingDir(MOTIONDB_ASSIMP_BVH_DIR); }

std::string CliPath() { return MOTIONDB_CLI_PATH; }

std::filesystem::path MakeTempDir(const std::string& prefix) {
  std::string pattern = (std::filesystem::path(::testing::TempDir()) / (prefix + "_XXXXXX"));
  if (mkdtemp(pattern.data()) == nullptr) {
    ADD_FAILURE() << "mkdtemp " << pattern << ": " << std::strerror(errno);
  }
  return pattern;
}

absl::StatusOr<TlsFiles> MakeTlsCertificate(const std::filesystem::path& dir) {
  if (std::system("command -v openssl >/dev/null 2>&1") != 0) {
    return absl::NotFoundError("openssl is not installed; TLS tests need it to make a certificate");
  }
  const TlsFiles files{(dir / "cert.pem").string(), (dir / "key.pem").string()};
  const std::string command =
      "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
      "-addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout '" +
      files.key + "' -out '" + files.cert + "' >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0) return absl::InternalError("failed: " + command);
  return files;
}

CommandResult RunCli(const std::vector<std::string>& args) {
  static int calls = 0;
  const std::string err_path = ::testing::TempDir() + "/cli_stderr_" + std::to_string(::getpid()) +
                               "_" + std::to_string(calls++);
  std::string command = "'" + CliPath() + "'";
  for (const std::string& arg : args) {
    std::string quoted = "'";
    for (char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    command += " " + quoted + "'";
  }
  command += " 2>'" + err_path + "'";
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) {
    ADD_FAILURE() << "cannot run " << command;
    return result;
  }
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.out.append(buffer, n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.err = ReadFileOrDie(err_path);
  std::filesystem::remove(err_path);
  return result;
}

std::vector<std::filesystem::path> BvhFilesUnder(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() == ".bvh")
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ReadFileOrDie(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    ADD_FAILURE() << "cannot read " << path;
    return "";
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

double MaxRotationError(const Clip& a, const Clip& b) {
  double worst = 0.0;
  for (int f = 0; f < a.frame_count(); ++f) {
    for (int j = 0; j < a.skeleton().joint_count(); ++j) {
      worst = std::max(worst, AngleBetween(a.rotation(f, j), b.rotation(f, j)));
    }
  }
  return worst;
}

double MaxRelativePositionError(const Clip& a, const Clip& b) {
  double worst = 0.0;
  for (int f = 0; f < a.frame_count(); ++f) {
    for (Eigen::Index slot = 0; slot < a.positions().cols() / 3; ++slot) {
      const Eigen::Vector3d pa = a.positions().block<1, 3>(f, 3 * slot).transpose();
      const Eigen::Vector3d pb = b.positions().block<1, 3>(f, 3 * slot).transpose();
      const double scale = std::max({1e-12, pa.norm(), pb.norm()});
      worst = std::max(worst, (pa - pb).norm() / scale);
    }
  }
  return worst;
}

}  // namespace motiondb::testing
