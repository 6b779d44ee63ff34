#pragma once
// The text of every JSON file wul3d writes (frames.jsonl, summary.json, objects.json,
// intrinsics.json, calibrations, recording.json, eval --json): one place, so that no
// string in it can make the write fail.
#include <nlohmann/json.hpp>
#include <string>

namespace wul3d {

/// `j` as text (`indent` as nlohmann::json::dump: -1 one line), valid UTF-8 whatever its
/// strings hold: a byte that is not part of a valid UTF-8 sequence (a frame folder or an
/// input path named in another encoding, "\xff\xfe") is written as U+FFFD, where dump()
/// would throw type_error.316 and lose the line or the file. Valid text is unchanged.
inline std::string json_text(const nlohmann::json& j, int indent = -1) {
    return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace wul3d
