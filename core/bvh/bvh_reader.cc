#include "core/bvh/bvh_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>
#include <system_error>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "util/file_io.h"
#include "util/name_text.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb {
namespace {

constexpr double kDegreesToRadians = std::numbers::pi / 180.0;

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
bool IsSpace(char c) { return IsBlank(c) || c == '\n'; }

// How a token is shown in an error: quoted and shortened, or named when it is not text.
std::string Describe(absl::string_view token) {
  if (token.empty()) return "end of file";
  for (char c : token) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) return "binary data";
  }
  if (token.size() > 40) return absl::StrCat("'", token.substr(0, 40), "...'");
  return absl::StrCat("'", token, "'");
}

absl::Status ErrorAt(int line, absl::string_view expected, absl::string_view found) {
  return absl::InvalidArgumentError(
      absl::StrCat("line ", line, ": expected ", expected, ", found ", Describe(found)));
}

// Parses a whole token as a finite double (E-notation and a leading '+' allowed).
std::optional<double> ParseDouble(absl::string_view token) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') ++begin;
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

// A forward cursor over the text that counts lines.
class Scanner {
 public:
  explicit Scanner(absl::string_view text) : text_(text) {}

  // The next whitespace-delimited token, or "" at the end; token_line() is its line.
  absl::string_view NextToken() {
    SkipSpace();
    token_line_ = line_;
    const size_t start = pos_;
    while (pos_ < text_.size() && !IsSpace(text_[pos_])) ++pos_;
    if (pos_ == text_.size()) reached_end_ = true;
    return text_.substr(start, pos_ - start);
  }

  // The rest of the current line, without surrounding blanks; advances past the newline.
  absl::string_view RestOfLine() {
    while (pos_ < text_.size() && IsBlank(text_[pos_])) ++pos_;
    token_line_ = line_;
    const size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    size_t stop = pos_;
    while (stop > start && IsBlank(text_[stop - 1])) --stop;
    if (pos_ < text_.size()) {
      ++pos_;
      ++line_;
    } else {
      reached_end_ = true;
    }
    return text_.substr(start, stop - start);
  }

  int token_line() const { return token_line_; }
  int line() const { return line_; }
  size_t pos() const { return pos_; }
  // Whether a token or line ran into the end of the text: more text could have continued it.
  bool reached_end() const { return reached_end_; }

 private:
  void SkipSpace() {
    while (pos_ < text_.size() && IsSpace(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }

  absl::string_view text_;
  size_t pos_ = 0;
  int line_ = 1;
  int token_line_ = 1;
  bool reached_end_ = false;
};

absl::Status Expect(Scanner& scanner, absl::string_view keyword) {
  const absl::string_view token = scanner.NextToken();
  if (token != keyword) {
    return ErrorAt(scanner.token_line(), absl::StrCat("'", keyword, "'"), token);
  }
  return absl::OkStatus();
}

absl::StatusOr<Eigen::Vector3d> ParseOffset(Scanner& scanner) {
  Eigen::Vector3d offset;
  for (int axis = 0; axis < 3; ++axis) {
    const absl::string_view token = scanner.NextToken();
    const std::optional<double> value = ParseDouble(token);
    if (!value) return ErrorAt(scanner.token_line(), "a finite number in OFFSET", token);
    offset[axis] = *value;
  }
  return offset;
}

absl::StatusOr<std::vector<Channel>> ParseChannels(Scanner& scanner) {
  const absl::string_view count_token = scanner.NextToken();
  int count = -1;
  const auto [ptr, ec] =
      std::from_chars(count_token.data(), count_token.data() + count_token.size(), count);
  if (ec != std::errc() || ptr != count_token.data() + count_token.size() || count < 0 ||
      count > 6) {
    return ErrorAt(scanner.token_line(), "a channel count from 0 to 6", count_token);
  }
  std::vector<Channel> channels;
  for (int i = 0; i < count; ++i) {
    const absl::string_view name = scanner.NextToken();
    const std::optional<Channel> channel = ParseChannel(name);
    if (!channel) {
      return ErrorAt(scanner.token_line(),
                     "a channel name (Xposition, Yposition, Zposition, Xrotation, Yrotation or "
                     "Zrotation)",
                     name);
    }
    channels.push_back(*channel);
  }
  return channels;
}

// A joint name: the rest of the line after ROOT/JOINT (names may hold colons and spaces).
// Some exporters put the opening brace on the same line; `brace_consumed` reports it.
absl::StatusOr<std::string> ParseJointName(Scanner& scanner, bool& brace_consumed) {
  absl::string_view name = scanner.RestOfLine();
  brace_consumed = false;
  if (name.size() > 1 && name.back() == '{') {
    name.remove_suffix(1);
    while (!name.empty() && IsBlank(name.back())) name.remove_suffix(1);
    brace_consumed = true;
  }
  // Braces inside a name could not be written back unambiguously.
  const bool bad = name.empty() || std::any_of(name.begin(), name.end(), [](char c) {
                     const auto u = static_cast<unsigned char>(c);
                     return u < 0x20 || u == 0x7f || c == '{' || c == '}';
                   });
  if (bad) return ErrorAt(scanner.token_line(), "a joint name without braces", name);
  // Names are shown in listings and answers, which carry UTF-8 only.
  MOTIONDB_RETURN_IF_ERROR(
      Prefixed(absl::StrCat("line ", scanner.token_line()), CheckNameText("joint name", name)));
  return std::string(name);
}

absl::StatusOr<std::vector<Joint>> ParseHierarchy(Scanner& scanner, const BvhReadOptions& options) {
  const absl::string_view first = scanner.NextToken();
  if (first.empty()) return absl::InvalidArgumentError("empty file");
  if (first != "HIERARCHY") return ErrorAt(scanner.token_line(), "'HIERARCHY'", first);
  MOTIONDB_RETURN_IF_ERROR(Expect(scanner, "ROOT"));

  std::vector<Joint> joints;
  std::vector<int> open;  // the joints whose '{' is not closed yet, innermost last
  std::vector<int> joint_lines;
  auto open_joint = [&](int parent) -> absl::Status {
    if (static_cast<int>(joints.size()) >= options.max_joints) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "line ", scanner.token_line(), ": more than ", options.max_joints, " joints"));
    }
    bool brace_consumed = false;
    MOTIONDB_ASSIGN_OR_RETURN(std::string name, ParseJointName(scanner, brace_consumed));
    joint_lines.push_back(scanner.token_line());
    if (!brace_consumed) MOTIONDB_RETURN_IF_ERROR(Expect(scanner, "{"));
    Joint joint;
    joint.name = std::move(name);
    joint.parent = parent;
    joints.push_back(std::move(joint));
    open.push_back(static_cast<int>(joints.size()) - 1);
    return absl::OkStatus();
  };
  MOTIONDB_RETURN_IF_ERROR(open_joint(-1));

  while (!open.empty()) {
    const absl::string_view token = scanner.NextToken();
    Joint& joint = joints[open.back()];
    if (token == "OFFSET") {
      MOTIONDB_ASSIGN_OR_RETURN(joint.offset, ParseOffset(scanner));
    } else if (token == "CHANNELS") {
      const int line = scanner.token_line();
      MOTIONDB_ASSIGN_OR_RETURN(joint.channels, ParseChannels(scanner));
      // Validate the channel mix here, while the line is known.
      if (absl::Status status = ValidateJointChannels(joint); !status.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("line ", line, ": ", status.message()));
      }
    } else if (token == "JOINT") {
      MOTIONDB_RETURN_IF_ERROR(open_joint(open.back()));
    } else if (token == "End") {
      MOTIONDB_RETURN_IF_ERROR(Expect(scanner, "Site"));
      if (joint.end_site)
        return ErrorAt(scanner.token_line(), "one End Site per joint", "End Site");
      MOTIONDB_RETURN_IF_ERROR(Expect(scanner, "{"));
      MOTIONDB_RETURN_IF_ERROR(Expect(scanner, "OFFSET"));
      MOTIONDB_ASSIGN_OR_RETURN(joint.end_site, ParseOffset(scanner));
      MOTIONDB_RETURN_IF_ERROR(Expect(scanner, "}"));
    } else if (token == "}") {
      open.pop_back();
    } else {
      return ErrorAt(scanner.token_line(), "'OFFSET', 'CHANNELS', 'JOINT', 'End Site' or '}'",
                     token);
    }
  }
  // Reported here rather than by Skeleton::Create so that the error names both lines.
  absl::flat_hash_map<absl::string_view, int> first_use;
  for (size_t i = 0; i < joints.size(); ++i) {
    const auto [it, inserted] = first_use.emplace(joints[i].name, static_cast<int>(i));
    if (!inserted) {
      return absl::InvalidArgumentError(absl::StrCat("line ", joint_lines[i], ": joint name '",
                                                     joints[i].name, "' is already used on line ",
                                                     joint_lines[it->second]));
    }
  }
  return joints;
}

// Reads "KEY VALUE" where the value may also be glued to the key ("Frames:51").
absl::StatusOr<absl::string_view> ValueAfter(Scanner& scanner, absl::string_view key) {
  absl::string_view token = scanner.NextToken();
  if (token.substr(0, key.size()) != key) {
    return ErrorAt(scanner.token_line(), absl::StrCat("'", key, "'"), token);
  }
  token.remove_prefix(key.size());
  return token.empty() ? scanner.NextToken() : token;
}

// Per-channel instructions for turning a frame row into quaternions and positions.
struct RowLayout {
  struct JointLayout {
    std::optional<EulerOrder> order;
    std::array<int, 3> rotation_channel{};  // value index of each Euler angle, in listed order
    int position_slot = -1;
    std::array<int, 3> position_channel{};  // value index of x, y, z
  };
  std::vector<JointLayout> joints;
  struct Value {
    int joint;
    Channel channel;
  };
  std::vector<Value> value_channels;  // what each value of a row is, in file order

  explicit RowLayout(const Skeleton& skeleton) {
    int value = 0;
    for (int j = 0; j < skeleton.joint_count(); ++j) {
      JointLayout layout;
      layout.order =
          skeleton.has_rotation(j) ? std::optional(skeleton.rotation_order(j)) : std::nullopt;
      layout.position_slot = skeleton.position_slot(j);
      int rotations = 0;
      for (Channel c : skeleton.joint(j).channels) {
        value_channels.push_back({j, c});
        const int axis = static_cast<int>(c) % 3;
        if (c >= Channel::kXrotation) {
          layout.rotation_channel[rotations++] = value;
        } else {
          layout.position_channel[axis] = value;
        }
        ++value;
      }
      joints.push_back(layout);
    }
  }

  void Apply(const double* values, double* rotation_row, double* position_row) const {
    for (size_t j = 0; j < joints.size(); ++j) {
      const JointLayout& layout = joints[j];
      Quat q = Quat::Identity();
      if (layout.order) {
        const Eigen::Vector3d angles(values[layout.rotation_channel[0]] * kDegreesToRadians,
                                     values[layout.rotation_channel[1]] * kDegreesToRadians,
                                     values[layout.rotation_channel[2]] * kDegreesToRadians);
        q = EulerToQuaternion(angles, *layout.order);
      }
      double* out = rotation_row + 4 * j;
      out[0] = q.w();
      out[1] = q.x();
      out[2] = q.y();
      out[3] = q.z();
      if (layout.position_slot >= 0) {
        for (int axis = 0; axis < 3; ++axis) {
          position_row[3 * layout.position_slot + axis] = values[layout.position_channel[axis]];
        }
      }
    }
  }
};

// What the lines from MOTION to the frame time say.
struct MotionHeader {
  int64_t frames = 0;   // as the header says
  int frames_line = 0;  // the line of `Frames:`
  double frame_time = 0.0;
};

absl::StatusOr<MotionHeader> ParseMotionHeader(Scanner& scanner, const BvhReadOptions& options) {
  {
    const absl::string_view token = scanner.NextToken();
    if (token == "ROOT") {
      return absl::InvalidArgumentError(absl::StrCat("line ", scanner.token_line(),
                                                     ": a second ROOT hierarchy is not supported"));
    }
    if (token != "MOTION") return ErrorAt(scanner.token_line(), "'MOTION'", token);
  }
  MotionHeader header;
  MOTIONDB_ASSIGN_OR_RETURN(const absl::string_view frames_token, ValueAfter(scanner, "Frames:"));
  header.frames_line = scanner.token_line();
  {
    const char* end = frames_token.data() + frames_token.size();
    const auto [ptr, ec] = std::from_chars(frames_token.data(), end, header.frames);
    if (ec == std::errc::result_out_of_range ||
        (ec == std::errc() && ptr == end && header.frames > options.max_frames)) {
      return absl::ResourceExhaustedError(
          absl::StrCat("line ", header.frames_line, ": frame count ", frames_token,
                       " is over the limit of ", options.max_frames));
    }
    if (ec != std::errc() || ptr != end || header.frames < 0) {
      return ErrorAt(header.frames_line, "a non-negative frame count after 'Frames:'",
                     frames_token);
    }
  }
  MOTIONDB_RETURN_IF_ERROR(Expect(scanner, "Frame"));
  MOTIONDB_ASSIGN_OR_RETURN(const absl::string_view time_token, ValueAfter(scanner, "Time:"));
  const std::optional<double> frame_time = ParseDouble(time_token);
  if (!frame_time || *frame_time <= 0.0) {
    return ErrorAt(scanner.token_line(), "a positive frame time after 'Frame Time:'", time_token);
  }
  header.frame_time = *frame_time;
  const int time_line = scanner.token_line();
  if (absl::string_view rest = scanner.RestOfLine(); !rest.empty()) {
    return ErrorAt(time_line, "end of line after the frame time", rest);
  }
  return header;
}

}  // namespace

// The frame rows: parsed a line at a time into the clip's matrices as they grow.
class BvhStreamReader::Motion {
 public:
  // `first_line`: the line number of the first row; `bytes_hint`: the size of the text of the
  // rows when known (the whole text was given), else of what has arrived of it.
  Motion(std::shared_ptr<const Skeleton> skeleton, const MotionHeader& header, int first_line,
         size_t bytes_hint, const BvhReadOptions& options)
      : skeleton_(std::move(skeleton)),
        header_(header),
        options_(options),
        layout_(*skeleton_),
        values_(skeleton_->channel_count()),
        line_(first_line),
        row_bytes_(static_cast<int64_t>(sizeof(double)) *
                   (4 * skeleton_->joint_count() + 3 * skeleton_->position_joint_count())) {
    // Each value takes at least two bytes, which bounds the rows the text can hold; beyond the
    // hint the matrices grow by doubling, up to what the header says and then past it.
    capacity_ = static_cast<Eigen::Index>(std::min<size_t>(static_cast<size_t>(header.frames),
                                                           bytes_hint / (2 * values_.size()) + 1));
    capacity_ = std::clamp<Eigen::Index>(capacity_, 1, options.max_clip_bytes / row_bytes_ + 1);
    rotations_.resize(capacity_, 4 * skeleton_->joint_count());
    positions_.resize(capacity_, 3 * skeleton_->position_joint_count());
  }

  // Every line of `text`, which ends with a newline.
  absl::Status ParseLines(absl::string_view text) {
    const char* p = text.data();
    const char* const end = p + text.size();
    while (p < end) {
      const char* newline = static_cast<const char*>(std::memchr(p, '\n', end - p));
      MOTIONDB_RETURN_IF_ERROR(ParseLine(absl::string_view(p, newline - p), false));
      p = newline + 1;
      if (short_row_) return TextGoesOn(p < end);
    }
    return absl::OkStatus();
  }

  // One line without its newline; `unterminated`: the text ended inside it.
  absl::Status ParseLine(absl::string_view text, bool unterminated) {
    MOTIONDB_RETURN_IF_ERROR(CheckRowLength(text.size()));
    const int channels = static_cast<int>(values_.size());
    const char* p = text.data();
    const char* const end = p + text.size();
    int count = 0;
    while (true) {
      while (p < end && IsBlank(*p)) ++p;
      if (p == end) break;
      const char* start = p;
      if (*p == '+') ++p;
      double value;
      const auto [next, ec] = std::from_chars(p, end, value);
      if (ec != std::errc() || (next < end && !IsSpace(*next))) {
        const char* stop = start;
        while (stop < end && !IsSpace(*stop)) ++stop;
        return ErrorAt(line_, absl::StrCat("a number (value ", count + 1, " of ", channels, ")"),
                       absl::string_view(start, stop - start));
      }
      if (!std::isfinite(value)) {
        return absl::InvalidArgumentError(
            absl::StrCat("line ", line_, ": value ", count + 1, " is ",
                         absl::string_view(start, next - start), "; expected a finite number"));
      }
      if (count == channels) {
        return absl::InvalidArgumentError(
            absl::StrCat("line ", line_, ": expected ", channels, " values, found more"));
      }
      if (const RowLayout::Value what = layout_.value_channels[count];
          what.channel >= Channel::kXrotation &&
          std::abs(value) > options_.max_abs_rotation_degrees) {
        return absl::InvalidArgumentError(absl::StrCat(
            "line ", line_, ": value ", count + 1, " (", skeleton_->joint(what.joint).name, " ",
            ChannelName(what.channel), ") is ", absl::string_view(start, next - start),
            " degrees; rotations beyond +-", options_.max_abs_rotation_degrees, " are refused"));
      }
      values_[count++] = value;
      p = next;
    }
    if (count != 0) MOTIONDB_RETURN_IF_ERROR(AddRow(count, unterminated));
    ++line_;
    return absl::OkStatus();
  }

  // RESOURCE_EXHAUSTED when the line being read is over the options' limit.
  absl::Status CheckRowLength(size_t bytes) const {
    if (static_cast<int64_t>(bytes) <= options_.max_row_bytes) return absl::OkStatus();
    return absl::ResourceExhaustedError(absl::StrCat("line ", line_,
                                                     ": a frame row longer than the limit of ",
                                                     options_.max_row_bytes, " bytes"));
  }

  // After a row short of values whose line ended where the text so far ends: whether more text
  // follows decides its error (ReadBvh says "truncated" only of the text's last line).
  bool has_short_row() const { return short_row_.has_value(); }
  absl::Status TextGoesOn(bool goes_on) const {
    return goes_on ? ShortRowError(/*truncated=*/false) : absl::OkStatus();
  }

  absl::StatusOr<BvhReadResult> Finish() {
    if (short_row_) return ShortRowError(/*truncated=*/true);
    if (rows_ == 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          "line ", line_, ": expected frame rows after 'Frame Time:', found end of file"));
    }
    rotations_.conservativeResize(rows_, Eigen::NoChange);
    positions_.conservativeResize(rows_, Eigen::NoChange);
    std::vector<std::string> warnings;
    if (rows_ != header_.frames) {
      warnings.push_back(absl::StrCat("line ", header_.frames_line,
                                      ": header says Frames: ", header_.frames,
                                      " but the file holds ", rows_, " frame rows; using ", rows_));
    }
    MOTIONDB_ASSIGN_OR_RETURN(
        Clip clip, Clip::Create(std::move(skeleton_), header_.frame_time, std::move(rotations_),
                                std::move(positions_)));
    return BvhReadResult{std::move(clip), std::move(warnings)};
  }

 private:
  struct ShortRow {
    int line;
    int count;
  };

  absl::Status ShortRowError(bool truncated) const {
    return absl::InvalidArgumentError(
        absl::StrCat("line ", short_row_->line, ": expected ", values_.size(), " values, found ",
                     short_row_->count, truncated ? " (the file is truncated)" : ""));
  }

  absl::Status AddRow(int count, bool unterminated) {
    if (count != static_cast<int>(values_.size())) {
      short_row_ = ShortRow{line_, count};
      return unterminated ? ShortRowError(/*truncated=*/true) : absl::OkStatus();
    }
    if (rows_ == options_.max_frames) {
      return absl::ResourceExhaustedError(
          absl::StrCat("line ", line_, ": more than ", options_.max_frames, " frames"));
    }
    if ((rows_ + 1) * row_bytes_ > options_.max_clip_bytes) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "line ", line_, ": the clip would take more than ", options_.max_clip_bytes,
          " bytes of memory (", row_bytes_, " a frame for ", skeleton_->joint_count(), " joints)"));
    }
    if (rows_ == capacity_) {
      // realloc: large blocks are mapped, so growing them moves pages rather than copying.
      capacity_ = rows_ < header_.frames ? std::min<Eigen::Index>(2 * capacity_, header_.frames)
                                         : 2 * capacity_;
      rotations_.conservativeResize(capacity_, Eigen::NoChange);
      positions_.conservativeResize(capacity_, Eigen::NoChange);
    }
    layout_.Apply(values_.data(), rotations_.row(rows_).data(), positions_.row(rows_).data());
    ++rows_;
    return absl::OkStatus();
  }

  std::shared_ptr<const Skeleton> skeleton_;
  MotionHeader header_;
  BvhReadOptions options_;
  RowLayout layout_;
  std::vector<double> values_;  // one row's, in file order
  int line_;                    // of the next line
  int64_t row_bytes_;           // a frame's in the matrices
  std::optional<ShortRow> short_row_;
  Eigen::Index rows_ = 0;
  Eigen::Index capacity_ = 0;
  RowMatrixXd rotations_;
  RowMatrixXd positions_;
};

BvhStreamReader::BvhStreamReader(const BvhReadOptions& options) : options_(options) {}
BvhStreamReader::~BvhStreamReader() = default;
BvhStreamReader::BvhStreamReader(BvhStreamReader&&) noexcept = default;
BvhStreamReader& BvhStreamReader::operator=(BvhStreamReader&&) noexcept = default;

absl::Status BvhStreamReader::Append(absl::string_view piece) {
  MOTIONDB_RETURN_IF_ERROR(status_);
  bytes_ += static_cast<int64_t>(piece.size());
  if (bytes_ > options_.max_bytes) {
    status_ = absl::ResourceExhaustedError(absl::StrCat(
        "input is ", bytes_, " bytes or more, over the limit of ", options_.max_bytes));
  } else {
    status_ = motion_ ? AppendToMotion(piece) : AppendToHeader(piece);
  }
  return status_;
}

absl::StatusOr<BvhReadResult> BvhStreamReader::Finish() {
  MOTIONDB_RETURN_IF_ERROR(status_);
  if (!motion_) {
    const std::string text = std::move(pending_);
    pending_.clear();
    status_ = ParseHeader(text, /*final=*/true);
  }
  if (status_.ok() && !pending_.empty()) {
    status_ = motion_->ParseLine(pending_, /*unterminated=*/true);
  }
  MOTIONDB_RETURN_IF_ERROR(status_);
  status_ = absl::FailedPreconditionError("BvhStreamReader::Finish was called already");
  return motion_->Finish();
}

absl::Status BvhStreamReader::AppendToHeader(absl::string_view piece) {
  // Parsed in place when nothing is pending: a whole file is not copied.
  if (pending_.empty()) {
    MOTIONDB_RETURN_IF_ERROR(ParseHeader(piece, /*final=*/false));
    if (!motion_) pending_.assign(piece.data(), piece.size());
  } else {
    pending_.append(piece.data(), piece.size());
    if (pending_.size() < next_header_attempt_) return absl::OkStatus();
    std::string text = std::move(pending_);
    pending_.clear();
    MOTIONDB_RETURN_IF_ERROR(ParseHeader(text, /*final=*/false));
    if (!motion_) pending_ = std::move(text);
  }
  if (!motion_) next_header_attempt_ = 2 * pending_.size();
  return absl::OkStatus();
}

absl::Status BvhStreamReader::ParseHeader(absl::string_view text, bool final) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  Scanner scanner(text);
  // An error or a header that ran into the end of the text may be a piece's cut: wait for more.
  // A parse that went past the header's limit is refused whether or not it ended there, so that
  // the whole text and any pieces of it give the same error.
  auto wait_for_more = [&]() -> absl::StatusOr<bool> {
    if (static_cast<int64_t>(scanner.pos()) > options_.max_header_bytes) {
      return absl::ResourceExhaustedError(
          absl::StrCat("the header (HIERARCHY to the frame time) is over the limit of ",
                       options_.max_header_bytes, " bytes"));
    }
    return !final && scanner.reached_end();
  };
  absl::StatusOr<std::vector<Joint>> joints = ParseHierarchy(scanner, options_);
  MOTIONDB_ASSIGN_OR_RETURN(bool wait, wait_for_more());
  if (wait) return absl::OkStatus();
  MOTIONDB_RETURN_IF_ERROR(joints.status());
  MOTIONDB_ASSIGN_OR_RETURN(Skeleton skeleton, Skeleton::Create(*std::move(joints)));
  const absl::StatusOr<MotionHeader> header = ParseMotionHeader(scanner, options_);
  MOTIONDB_ASSIGN_OR_RETURN(wait, wait_for_more());
  if (wait) return absl::OkStatus();
  MOTIONDB_RETURN_IF_ERROR(header.status());
  if (skeleton.channel_count() == 0) {
    return absl::InvalidArgumentError("the hierarchy has no channels");
  }
  const absl::string_view rows = text.substr(scanner.pos());
  motion_ = std::make_unique<Motion>(std::make_shared<const Skeleton>(std::move(skeleton)), *header,
                                     scanner.line(), rows.size(), options_);
  return AppendToMotion(rows);
}

absl::Status BvhStreamReader::AppendToMotion(absl::string_view piece) {
  if (motion_->has_short_row()) return motion_->TextGoesOn(!piece.empty());
  if (!pending_.empty()) {
    const size_t newline = piece.find('\n');
    if (newline == absl::string_view::npos) {
      pending_.append(piece.data(), piece.size());
      return motion_->CheckRowLength(pending_.size());
    }
    pending_.append(piece.data(), newline);
    MOTIONDB_RETURN_IF_ERROR(motion_->ParseLine(pending_, /*unterminated=*/false));
    pending_.clear();
    piece.remove_prefix(newline + 1);
    if (motion_->has_short_row()) return motion_->TextGoesOn(!piece.empty());
  }
  const size_t last_newline = piece.rfind('\n');
  if (last_newline != absl::string_view::npos) {
    MOTIONDB_RETURN_IF_ERROR(motion_->ParseLines(piece.substr(0, last_newline + 1)));
    piece.remove_prefix(last_newline + 1);
    if (motion_->has_short_row()) return motion_->TextGoesOn(!piece.empty());
  }
  pending_.assign(piece.data(), piece.size());
  return motion_->CheckRowLength(pending_.size());
}

absl::StatusOr<BvhReadResult> ReadBvh(absl::string_view text, const BvhReadOptions& options) {
  if (static_cast<int64_t>(text.size()) > options.max_bytes) {
    return absl::ResourceExhaustedError(
        absl::StrCat("input is ", text.size(), " bytes, over the limit of ", options.max_bytes));
  }
  BvhStreamReader reader(options);
  MOTIONDB_RETURN_IF_ERROR(reader.Append(text));
  return reader.Finish();
}

absl::StatusOr<BvhReadResult> ReadBvhFile(const std::string& path, const BvhReadOptions& options) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, ReadFileBytes(path, options.max_bytes));
  return Prefixed(path, ReadBvh(text, options));
}

}  // namespace motiondb
