// The run states db/ owns: their text never changes (databases, Slurm task
// files and the CLI hold it), and an unknown text is refused by name.
#include "db/run_state.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using flocsim::db::kAllRunStates;
using flocsim::db::run_state_from_string;
using flocsim::db::RunState;

namespace {

TEST(ResultsDbRunState, EveryStateRoundTripsThroughItsText) {
  std::set<std::string> names;
  for (RunState s : kAllRunStates) {
    const std::string text = to_string(s);
    EXPECT_EQ(run_state_from_string(text), s) << text;
    names.insert(text);
  }
  EXPECT_EQ(names.size(), std::size(kAllRunStates));  // no two states share a text
}

TEST(ResultsDbRunState, TextsAreTheStoredOnesInStatusOrder) {
  // What existing databases hold and `flocsim sweep status` prints, in its order.
  std::vector<std::string> texts;
  for (RunState s : kAllRunStates) texts.push_back(to_string(s));
  EXPECT_EQ(texts, (std::vector<std::string>{"pending", "running", "completed", "failed", "refused",
                                             "interrupted", "lost"}));
  std::ostringstream shown;
  shown << RunState::kInterrupted;
  EXPECT_EQ(shown.str(), "interrupted");
}

TEST(ResultsDbRunState, UnknownTextIsRefusedByName) {
  for (const char* bad : {"cancelled", "Completed", "", " pending", "done"}) {
    try {
      run_state_from_string(bad);
      ADD_FAILURE() << "\"" << bad << "\" was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("unknown run state \"" + std::string(bad) + "\""), std::string::npos)
          << what;
      EXPECT_NE(what.find("pending, running, completed"), std::string::npos) << what;
    }
  }
}

TEST(ResultsDbRunState, JsonHoldsTheTextNotTheEnumNumber) {
  const nlohmann::json j = std::vector<RunState>{RunState::kPending, RunState::kLost};
  EXPECT_EQ(j.dump(), R"(["pending","lost"])");
  EXPECT_EQ(j.get<std::vector<RunState>>(),
            (std::vector<RunState>{RunState::kPending, RunState::kLost}));
  EXPECT_THROW(nlohmann::json("stopped").get<RunState>(), std::invalid_argument);
}

}  // namespace
