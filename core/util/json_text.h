#pragma once
// JSON text of a document whose strings may hold bytes that are not UTF-8 (a
// file name in Latin-1, a command line): nlohmann's dump() throws on them,
// which failed `bench --json` after all its work. Here such bytes become
// U+FFFD; everything else is written as dump() writes it.
#include <nlohmann/json.hpp>
#include <string>

namespace accelviz {

/// j.dump(indent) with invalid UTF-8 replaced (indent -1: one line).
inline std::string json_text(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

/// `text` with every byte that does not belong to a valid UTF-8 sequence
/// replaced by U+FFFD (for PNG iTXt text, which must be UTF-8).
inline std::string valid_utf8(const std::string& text) {
  return nlohmann::json::parse(json_text(nlohmann::json(text))).get<std::string>();
}

}  // namespace accelviz
