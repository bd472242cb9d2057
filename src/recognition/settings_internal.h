// Internal helpers of pipeline*.cpp (not part of the public contract).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "recognition/pipeline.h"

namespace pb::detail {

// Every field of the settings, in declaration order (settings_to_json dumps it).
nlohmann::ordered_json settings_json(const RecognitionSettings& s);

}  // namespace pb::detail

namespace pb {
// InputError(file, field) for names not in descriptor_names() / refinement_names().
void check_descriptor_name(const std::string& name, const std::string& file, const std::string& field);
void check_refinement_name(const std::string& name, const std::string& file, const std::string& field);
}  // namespace pb
