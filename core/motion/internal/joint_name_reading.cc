#include "core/motion/internal/joint_name_reading.h"

#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_join.h"

namespace motiondb {
namespace {

struct Alias {
  absl::string_view stem;
  BodyPart part;
};

// The rigs' names for each part, as stems (tokens without side and digits, concatenated):
// MotionBuilder/HumanIK and Mixamo (UpLeg, Leg, ForeArm, ToeBase), CMU's BVH conversions
// (LowerBack, LeftHip/Knee/Ankle, LeftCollar, LeftElbow/Wrist) and ASF names (femur, tibia,
// humerus, radius, clavicle, thorax), Bandai (UpperLeg_L, LowerArm_L, Toes_L), 3ds Max Biped
// (Pelvis, Thigh, Calf, UpperArm, Forearm, Toe0), the Unreal mannequin (pelvis, spine_01, thigh_l,
// calf_l, ball_l, clavicle_l, upperarm_l, lowerarm_l) and VRM (upperLeg, lowerArm, upperChest).
// "hip" is the hips alone and an upper leg with a side ("LeftHip").
constexpr Alias kAliases[] = {
    {"hips", BodyPart::kHips},         {"pelvis", BodyPart::kHips},
    {"spine", BodyPart::kSpine},       {"lowerback", BodyPart::kSpine},
    {"ab", BodyPart::kSpine},          {"abdomen", BodyPart::kSpine},
    {"waist", BodyPart::kSpine},       {"torso", BodyPart::kSpine},
    {"chest", BodyPart::kChest},       {"upperchest", BodyPart::kChest},
    {"thorax", BodyPart::kChest},      {"upperback", BodyPart::kChest},
    {"neck", BodyPart::kNeck},         {"lowerneck", BodyPart::kNeck},
    {"upperneck", BodyPart::kNeck},    {"head", BodyPart::kHead},
    {"shoulder", BodyPart::kShoulder}, {"clavicle", BodyPart::kShoulder},
    {"collar", BodyPart::kShoulder},   {"upperarm", BodyPart::kUpperArm},
    {"arm", BodyPart::kUpperArm},      {"humerus", BodyPart::kUpperArm},
    {"forearm", BodyPart::kLowerArm},  {"lowerarm", BodyPart::kLowerArm},
    {"elbow", BodyPart::kLowerArm},    {"radius", BodyPart::kLowerArm},
    {"hand", BodyPart::kHand},         {"wrist", BodyPart::kHand},
    {"upleg", BodyPart::kUpperLeg},    {"upperleg", BodyPart::kUpperLeg},
    {"thigh", BodyPart::kUpperLeg},    {"femur", BodyPart::kUpperLeg},
    {"leg", BodyPart::kLowerLeg},      {"lowerleg", BodyPart::kLowerLeg},
    {"calf", BodyPart::kLowerLeg},     {"knee", BodyPart::kLowerLeg},
    {"shin", BodyPart::kLowerLeg},     {"tibia", BodyPart::kLowerLeg},
    {"foot", BodyPart::kFoot},         {"ankle", BodyPart::kFoot},
    {"toe", BodyPart::kToes},          {"toes", BodyPart::kToes},
    {"toebase", BodyPart::kToes},      {"ball", BodyPart::kToes},
};

// Words a one-letter side may be glued to ("lhand", "rfemur", "lhipjoint", "lfingers"): the
// aliases and the other paired parts of CMU's ASF names.
constexpr absl::string_view kGluedWords[] = {"hip",   "hipjoint", "fingers", "finger",  "thumb",
                                             "index", "middle",   "ring",    "pinky",   "hand",
                                             "femur", "tibia",    "foot",    "toes",    "toe",
                                             "wrist", "radius",   "humerus", "clavicle"};

// Tokens that name the rig, not the part: 3ds Max's "Bip01", MotionBuilder's "Character1_",
// VRoid's "J_Bip_" and its "C" for the centre line.
constexpr absl::string_view kRigWords[] = {"bip", "character", "j", "c"};

bool IsGluedWord(absl::string_view word) {
  for (const absl::string_view glued : kGluedWords) {
    if (word == glued) return true;
  }
  for (const Alias& alias : kAliases) {
    if (word == alias.stem) return true;
  }
  return false;
}

bool IsRigWord(absl::string_view word) {
  for (const absl::string_view rig : kRigWords) {
    if (word == rig) return true;
  }
  return false;
}

bool IsDigits(absl::string_view token) {
  return !token.empty() && absl::ascii_isdigit(static_cast<unsigned char>(token[0]));
}

// Splits at anything not a letter or digit, between a lower-case letter and an upper-case one
// ("upLeg"), before the last capital of a run followed by a lower-case letter ("LHip" -> "L",
// "Hip"), and between letters and digits; lower-cased.
std::vector<std::string> Tokens(absl::string_view name) {
  std::vector<std::string> tokens;
  std::string current;
  const auto flush = [&] {
    if (!current.empty()) tokens.push_back(absl::AsciiStrToLower(current));
    current.clear();
  };
  for (size_t i = 0; i < name.size(); ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (!absl::ascii_isalnum(c)) {
      flush();
      continue;
    }
    if (!current.empty()) {
      const auto last = static_cast<unsigned char>(current.back());
      const bool next_lower =
          i + 1 < name.size() && absl::ascii_islower(static_cast<unsigned char>(name[i + 1]));
      const bool case_break = absl::ascii_isupper(c) && (absl::ascii_islower(last) ||
                                                         (absl::ascii_isupper(last) && next_lower));
      const bool digit_break = absl::ascii_isdigit(c) != absl::ascii_isdigit(last);
      if (case_break || digit_break) flush();
    }
    current.push_back(static_cast<char>(c));
  }
  flush();
  return tokens;
}

// The side a token gives, and what it leaves of itself ("lhand" -> left, "hand").
std::pair<BodySide, std::string> SplitSide(const std::string& token) {
  if (token == "left" || token == "l") return {BodySide::kLeft, ""};
  if (token == "right" || token == "r") return {BodySide::kRight, ""};
  for (const auto& [prefix, side] : {std::pair{absl::string_view("left"), BodySide::kLeft},
                                     std::pair{absl::string_view("right"), BodySide::kRight}}) {
    if (token.size() > prefix.size() && absl::StartsWith(token, prefix) &&
        IsGluedWord(absl::string_view(token).substr(prefix.size()))) {
      return {side, token.substr(prefix.size())};
    }
  }
  if (token.size() > 1 && (token[0] == 'l' || token[0] == 'r') &&
      IsGluedWord(absl::string_view(token).substr(1))) {
    return {token[0] == 'l' ? BodySide::kLeft : BodySide::kRight, token.substr(1)};
  }
  return {BodySide::kNone, token};
}

}  // namespace

JointNameReading ReadJointName(absl::string_view name) {
  const size_t namespace_end = name.find_last_of(":|");
  if (namespace_end != absl::string_view::npos) name.remove_prefix(namespace_end + 1);
  JointNameReading reading;
  std::vector<std::string> kept;
  std::string stem;
  for (const std::string& token : Tokens(name)) {
    auto [side, rest] = SplitSide(token);
    if (side != BodySide::kNone && reading.side == BodySide::kNone) reading.side = side;
    if (side != BodySide::kNone && reading.side != side) rest = token;  // a second, other side
    if (rest.empty()) continue;
    if (!IsDigits(rest) && !IsRigWord(rest)) stem += rest;
    kept.push_back(std::move(rest));
  }
  reading.mirror_key = absl::StrJoin(kept, "_");
  for (const Alias& alias : kAliases) {
    if (stem == alias.stem) reading.part = alias.part;
  }
  if (stem == "hip" && reading.side != BodySide::kNone) reading.part = BodyPart::kUpperLeg;
  if (stem == "hip" && reading.side == BodySide::kNone) reading.part = BodyPart::kHips;
  const bool sided_part = reading.part >= BodyPart::kShoulder;
  if (sided_part != (reading.side != BodySide::kNone)) reading.part = BodyPart::kNone;
  return reading;
}

}  // namespace motiondb
