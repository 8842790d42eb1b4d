// What parse_suspension_case says when it refuses a case (a test failure if it
// accepts it): the case tests hold each refusal's message to what would work.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "engine/case/suspension_case.hpp"
#include "engine/input/input_reader.hpp"

namespace flocsim::cases {

inline std::string refusal(const nlohmann::json& doc) {
  try {
    parse_suspension_case(doc);
  } catch (const input::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << doc.dump();
  return "";
}

}  // namespace flocsim::cases
