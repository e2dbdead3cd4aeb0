// A pass program (sequence/pass_program.h) as JSON: how a job's plan keeps the passes it was
// planned with, so that a coordinator resuming the job runs those passes, whatever a later build
// would plan for the same settings.
#pragma once

#include "tessera/sequence/pass_program.h"

#include <nlohmann/json.hpp>

#include <string>

namespace tessera {

nlohmann::json to_json(const PassProgram& program);
/// Strict: every field named, of its type, and a sound program (program_error); false with
/// `error` naming what is wrong.
[[nodiscard]] bool program_from_json(const nlohmann::json& j, PassProgram& out, std::string& error);

}  // namespace tessera
