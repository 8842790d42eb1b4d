#pragma once
// The case as this version runs it: a case document of any scene read by its
// scene's parser, every default filled in (to_json()). What a run records as
// result.json's "case"; `flocsim query` and `flocsim post` filter a run that
// has no result yet on it (docs/orchestrator.md, "Filters").
#include <nlohmann/json.hpp>

namespace flocsim::cases {

// Throws input::InputError, as the parsers do, when the document is refused.
nlohmann::json resolved_case(const nlohmann::json& document);

}  // namespace flocsim::cases
