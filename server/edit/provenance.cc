#include "server/edit/provenance.h"

#include <nlohmann/json.hpp>

namespace motiondb::server {

std::string ProvenanceJson(const Provenance& provenance) {
  nlohmann::json sources = nlohmann::json::array();
  for (const SourceRange& source : provenance.sources) {
    sources.push_back({{"clip_id", source.clip_id},
                       {"first_frame", source.frames.first},
                       {"last_frame", source.frames.last}});
  }
  nlohmann::json parameters = nlohmann::json::object();
  if (!provenance.parameters_json.empty()) {
    parameters =
        nlohmann::json::parse(provenance.parameters_json, nullptr, /*allow_exceptions=*/false);
    if (parameters.is_discarded()) parameters = nlohmann::json::object();
  }
  return nlohmann::json{{"operator", provenance.op},
                        {"space", provenance.space},
                        {"sources", sources},
                        {"parameters", parameters}}
      .dump();
}

std::optional<Provenance> ParseProvenance(absl::string_view text) {
  if (text.empty()) return std::nullopt;
  const nlohmann::json in = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!in.is_object()) return std::nullopt;
  try {
    Provenance provenance;
    provenance.op = in.at("operator").get<std::string>();
    provenance.space = in.at("space").get<std::string>();
    for (const nlohmann::json& source : in.at("sources")) {
      provenance.sources.push_back(
          {source.at("clip_id").get<int64_t>(),
           {source.at("first_frame").get<int>(), source.at("last_frame").get<int>()}});
    }
    provenance.parameters_json = in.at("parameters").dump();
    return provenance;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

}  // namespace motiondb::server
