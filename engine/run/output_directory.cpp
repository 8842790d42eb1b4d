#include "engine/run/output_directory.hpp"

#include <algorithm>
#include <ctime>
#include <fstream>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "engine/case/scene.hpp"
#include "engine/case/suspension_case.hpp"
#include "engine/coupling/scheme.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/text/printable.hpp"

namespace flocsim::run {

namespace fs = std::filesystem;

namespace {

// What a run writes besides its log, checkpoint and result.
constexpr const char* kSnapshotFolders[] = {"fields", "spheres"};
constexpr const char* kOutputFiles[] = {"fields.xdmf", "spheres.xdmf", "series.h5",
                                        "progress.json"};

// A snapshot file of output::snapshot_file (step_NNNNNNNNNN.h5) or the
// temporary of one that a killed writer left (.step_NNNNNNNNNN.h5.tmp.*).
bool is_snapshot_name(const std::string& name) {
  auto snapshot = [](const std::string& n) {
    if (n.size() != 18 || n.rfind("step_", 0) != 0 || n.substr(15) != ".h5") return false;
    return std::all_of(n.begin() + 5, n.begin() + 15,
                       [](char ch) { return ch >= '0' && ch <= '9'; });
  };
  if (snapshot(name)) return true;
  const auto tmp = name.find(".tmp.");
  return name.size() > 1 && name[0] == '.' && tmp != std::string::npos &&
         snapshot(name.substr(1, tmp - 1));
}

// Removes the outputs of an earlier attempt of the same case, by name only.
void remove_stale_outputs(const fs::path& dir) {
  for (const char* folder : kSnapshotFolders) {
    const fs::path f = dir / folder;
    if (!fs::is_directory(fs::symlink_status(f))) continue;
    for (const auto& e : fs::directory_iterator(f))
      if (e.is_regular_file() && is_snapshot_name(e.path().filename().string()))
        fs::remove(e.path());
    if (fs::is_empty(f)) fs::remove(f);
  }
  for (const char* file : kOutputFiles)
    if (fs::is_regular_file(fs::symlink_status(dir / file))) fs::remove(dir / file);
}

// Throws when a place a run writes to is taken by something it did not write.
void refuse_foreign_outputs(const fs::path& dir) {
  std::vector<std::string> taken;
  for (const char* folder : kSnapshotFolders)
    if (fs::exists(fs::symlink_status(dir / folder))) taken.push_back(folder);
  for (const char* file : kOutputFiles)
    if (fs::exists(fs::symlink_status(dir / file))) taken.push_back(file);
  if (taken.empty()) return;
  std::string list;
  for (const auto& t : taken) list += (list.empty() ? "" : ", ") + (dir / t).string();
  throw input::InputError(list + ": in the place of this run's output, and " +
                          (dir / kRunRecord).string() +
                          " does not say a run of this case wrote it; flocsim removes only what "
                          "it wrote, so move it away or use another --out directory");
}

// Throws when a place a run writes to is a symbolic link: the log is appended
// to and the other files replaced, and through a link that is a file
// elsewhere (a user's), which `flocsim run` must never change.
void refuse_links(const fs::path& dir) {
  std::vector<std::string> names = {"run.log", "result.json", "checkpoint.h5", kRunRecord};
  for (const char* f : kOutputFiles) names.push_back(f);
  for (const char* f : kSnapshotFolders) names.push_back(f);
  std::string links;
  for (const std::string& n : names)
    if (fs::is_symlink(fs::symlink_status(dir / n)))
      links += (links.empty() ? "" : ", ") + (dir / n).string();
  if (!links.empty())
    throw input::InputError(links +
                            ": a symbolic link where this run writes its output; flocsim does not "
                            "write through links (the file it points to would change), so remove "
                            "the link or use another --out directory");
}

}  // namespace

namespace {
StartMode prepare(const fs::path& dir, bool resume, const nlohmann::json& case_json);
std::string difference_text(const nlohmann::json& recorded_case, const nlohmann::json& current_case,
                            const std::string& recorded_in, bool steps_may_grow);

// The case a completed run's result.json records (the run record's where it
// has none); null when neither says.
nlohmann::json completed_case(const fs::path& dir) {
  for (const char* file : {"result.json", kRunRecord}) {
    try {
      std::ifstream in(dir / file);
      const auto j = nlohmann::json::parse(in);
      if (j.contains("case") && j["case"].is_object()) return j["case"];
    } catch (const std::exception&) {
      // not readable: the next file may say
    }
  }
  return nullptr;
}
}  // namespace

namespace {
// --out as a message shows it: cut short past 120 characters.
std::string shown_path(const fs::path& dir) {
  return dir.string().size() > 120 ? dir.string().substr(0, 120) + "..." : dir.string();
}

void require_directory(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw input::InputError(dir.string() +
                            ": exists and is not a directory; --out must name a "
                            "directory");
}
}  // namespace

std::unique_ptr<output::FileLock> lock_output_directory(const fs::path& dir) {
  require_directory(dir);
  std::unique_ptr<output::FileLock> lock;
  long holder = 0;
  try {
    fs::create_directories(dir);
    lock = output::FileLock::try_lock(dir / "flocsim-run", &holder);
  } catch (const fs::filesystem_error& e) {
    // a name too long, a folder not writable: the reason, not the path again
    throw input::InputError("--out " + shown_path(dir) + ": cannot prepare the output directory (" +
                            e.code().message() + ")");
  } catch (const std::exception& e) {
    // the lock file cannot be made (a link where it goes, say)
    throw input::InputError("--out " + shown_path(dir) + ": cannot prepare the output directory (" +
                            e.what() + ")");
  }
  if (!lock && holder == -1) return nullptr;  // no locks on this file system: said in the log
  if (!lock)
    throw OutputDirectoryBusy(
        "--out " + shown_path(dir) + ": another flocsim" +
        (holder > 0 ? " (process " + std::to_string(holder) + ")" : std::string()) +
        " is writing to this directory now; two runs in one directory would overwrite each "
        "other's output, so wait for it to end (a --resume then goes on from its checkpoint) or "
        "give this run another --out");
  return lock;
}

StartMode prepare_output_directory(const fs::path& dir, bool resume,
                                   const nlohmann::json& case_json) {
  try {
    return prepare(dir, resume, case_json);
  } catch (const fs::filesystem_error& e) {
    // a name too long, a folder not writable: an input error, with the path cut short
    throw input::InputError("--out " + shown_path(dir) + ": cannot prepare the output directory (" +
                            e.code().message() + ")");
  }
}

namespace {
// Where an unreadable result.json is set aside (free_name adds .1, .2, ...).
constexpr const char* kUnreadableResult = "result.json.unreadable";

// Why a result.json is not a completed result ("" when it is one).
std::string damaged_result(const fs::path& file) {
  try {
    std::ifstream in(file);
    const auto j = nlohmann::json::parse(in);
    if (!j.is_object() || !j.contains("status") || j["status"] != "completed")
      return "holds no completed result (no \"status\": \"completed\")";
    return "";
  } catch (const std::exception&) {
    return "cannot be read as JSON (cut short?)";
  }
}

// Whether the run record in `dir` names this case.
bool recorded_as(const fs::path& dir, const nlohmann::json& case_json) {
  try {
    std::ifstream in(dir / kRunRecord);
    return resumable_under(nlohmann::json::parse(in).at("case"), case_json);
  } catch (const std::exception&) {
    return false;
  }
}

// `path`, or path.1, path.2, ... : the first name not taken.
fs::path free_name(const fs::path& path) {
  fs::path p = path;
  for (int k = 1; fs::exists(fs::symlink_status(p)); ++k)
    p = fs::path(path.string() + "." + std::to_string(k));
  return p;
}

StartMode prepare(const fs::path& dir, bool resume, const nlohmann::json& case_json) {
  require_directory(dir);
  fs::create_directories(dir);
  refuse_links(dir);
  bool completed = fs::exists(dir / "result.json");
  const bool checkpoint = fs::exists(dir / "checkpoint.h5");
  if (completed) {
    // A run writes result.json last and atomically, so one that cannot be read
    // was cut short by something else (a full disk, a copy): it completes
    // nothing. Under --resume it is set aside (renamed, never removed) and the
    // run goes on from its checkpoint or starts again; said "already
    // completed" and then failing on it, the run could never be resumed.
    const std::string damage = damaged_result(dir / "result.json");
    if (!damage.empty()) {
      // --resume is advised only where it would be taken: a checkpoint or
      // the run record says this case wrote the file
      const bool ours = checkpoint || recorded_as(dir, case_json);
      if (!resume && ours)
        throw input::InputError((dir / "result.json").string() + ": " + damage +
                                "; continue this case with --resume (the file is set aside as " +
                                kUnreadableResult + "), or use another --out directory");
      if (!ours)
        throw input::InputError(
            (dir / "result.json").string() + ": " + damage + ", and neither a checkpoint nor " +
            (dir / kRunRecord).string() +
            " says this case wrote it; move it away to run this case here, or use another "
            "--out directory");
      const fs::path aside = free_name(dir / kUnreadableResult);
      fs::rename(dir / "result.json", aside);
      const std::string note = (dir / "result.json").string() + ": " + damage + "; set aside as " +
                               aside.string() + ", the run " +
                               (checkpoint ? "continues from its checkpoint" : "starts again");
      RunLog(dir / "run.log", true).warning(note);
      std::cerr << "flocsim run: warning: " << text::printable(note) << "\n";
      completed = false;
    }
  }
  if (completed) {
    if (resume) {
      // "already completed" only for the case it completed: another case's
      // result is not this one's
      const nlohmann::json recorded = completed_case(dir);
      if (recorded.is_null())
        throw input::InputError((dir / "result.json").string() +
                                ": records no case, so it cannot be the result of this one; use "
                                "another --out directory");
      if (!completed_under(recorded, case_json))
        throw input::InputError(
            (dir / "result.json").string() + " is the result of a different case (" +
            difference_text(recorded, case_json, "the result", false) +
            "); nothing was run. Use another --out directory for this case, or give those "
            "fields their recorded values");
      return StartMode::already_completed;
    }
    throw input::InputError(
        (dir / "result.json").string() +
        " exists: the run in this directory has completed; use another --out directory");
  }
  if (checkpoint) {
    if (resume) return StartMode::from_checkpoint;
    throw input::InputError((dir / "checkpoint.h5").string() +
                            " exists: continue it with --resume, or use another --out directory");
  }
  const fs::path record = dir / kRunRecord;
  bool same_case = false;
  if (fs::exists(record)) {
    nlohmann::json recorded;
    try {
      std::ifstream in(record);
      recorded = nlohmann::json::parse(in).at("case");
    } catch (const std::exception&) {
      throw input::InputError(record.string() +
                              ": not a run record written by flocsim; move it away or use "
                              "another --out directory");
    }
    if (!resumable_under(recorded, case_json))
      throw input::InputError(dir.string() + " holds the output of a different case (" +
                              record.string() + ": " + case_differences(recorded, case_json) +
                              "); use another --out directory, or give those fields their "
                              "recorded values to continue it");
    same_case = true;
  }
  if (same_case)
    remove_stale_outputs(dir);
  else
    refuse_foreign_outputs(dir);
  output::write_file_atomically(
      record, nlohmann::json{{"case", case_json},
                             {"written_by", "flocsim run"},
                             {"what",
                              "the case whose output this directory holds; a fresh start "
                              "of the same case may replace its snapshots"}}
                      .dump(2) +
                  "\n");
  return StartMode::fresh;
}
}  // namespace

RunReport completed_run(const fs::path& dir, RunLog& log) {
  log.info("already completed: " + (dir / "result.json").string() + " is kept as it is");
  RunReport r;
  r.outcome = RunOutcome::completed;
  std::ifstream in(dir / "result.json");
  r.result = nlohmann::json::parse(in);
  return r;
}

RunReport failed_run(const fs::path& dir, const std::exception& e) {
  RunReport r;
  r.outcome = RunOutcome::failed;
  r.message = e.what();
  if (fs::is_directory(dir)) {
    try {
      RunLog(dir / "run.log", true).error(r.message);
    } catch (const std::exception&) {
      // the log cannot be written either (a full disk): the message still
      // reaches the caller, and through it stderr
    }
  }
  return r;
}

std::string utc_timestamp() {
  const std::time_t now = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buf;
}

namespace {
// The case with run control removed and the defaults of older checkpoints
// filled in, as resumable_under compares it. `steps_may_grow`: a fluid run's
// checkpoint may be continued to more steps.
nlohmann::json physics_only(nlohmann::json c, bool steps_may_grow = true) {
  for (const char* group : {"run", "protocol"}) {
    if (!c.contains(group)) continue;
    for (const char* key : {"threads", "progress_every_s", "checkpoint_every_s"})
      c[group].erase(key);
  }
  // where the lattice stepped (cases/device.hpp): a checkpoint moves between
  // devices, and a result is the same case's whichever device computed it
  c.erase("device");
  if (steps_may_grow && c.value("scene", "") == cases::scene_name(cases::Scene::fluid) &&
      c.contains("run"))
    c["run"].erase("steps");
  // checkpoints from before numerics.immersed_boundary or lubrication_model
  // existed: the one value each had then
  return cases::with_older_versions_models(std::move(c));
}

void list_differences(const nlohmann::json& was, const nlohmann::json& now,
                      const std::string& prefix, const std::string& recorded_in,
                      std::vector<std::string>& out) {
  std::set<std::string> keys;
  for (const auto& [k, v] : was.items()) keys.insert(k);
  for (const auto& [k, v] : now.items()) keys.insert(k);
  for (const auto& k : keys) {
    const bool in_was = was.contains(k), in_now = now.contains(k);
    if (in_was && in_now && was[k].is_object() && now[k].is_object()) {
      list_differences(was[k], now[k], prefix + k + ".", recorded_in, out);
    } else if (!in_was || !in_now || was[k] != now[k]) {
      out.push_back(prefix + k + " = " + (in_was ? was[k].dump() : "(absent)") + " in " +
                    recorded_in + ", " + (in_now ? now[k].dump() : "(absent)") + " now");
    }
  }
}
}  // namespace

bool resumable_under(const nlohmann::json& checkpoint_case, const nlohmann::json& current_case) {
  return physics_only(checkpoint_case) == physics_only(current_case);
}

bool completed_under(const nlohmann::json& result_case, const nlohmann::json& current_case) {
  return physics_only(result_case, false) == physics_only(current_case, false);
}

namespace {
// "field = old in RECORDED_IN, new now; ..." (the checkpoint's steps may grow,
// a result's may not)
std::string difference_text(const nlohmann::json& recorded_case, const nlohmann::json& current_case,
                            const std::string& recorded_in, bool steps_may_grow) {
  std::vector<std::string> lines;
  list_differences(physics_only(recorded_case, steps_may_grow),
                   physics_only(current_case, steps_may_grow), "", recorded_in, lines);
  std::string text;
  for (const auto& l : lines) text += (text.empty() ? "" : "; ") + l;
  return text;
}
}  // namespace

std::string case_differences(const nlohmann::json& checkpoint_case,
                             const nlohmann::json& current_case) {
  return difference_text(checkpoint_case, current_case, "the checkpoint", true);
}

RunReport blown_up_run(RunLog& log, const std::string& where, const std::string& what,
                       long last_good_checkpoint, const std::filesystem::path& checkpoint,
                       const std::string& likely_causes) {
  RunReport r;
  r.outcome = RunOutcome::failed;
  r.message = "numerical blow-up detected at " + where + ": " + what + ". " +
              (last_good_checkpoint >= 0
                   ? "The last good checkpoint (step " + std::to_string(last_good_checkpoint) +
                         ") is kept in " + checkpoint.string() + ". "
                   : std::string("No checkpoint had been written yet. ")) +
              "Likely causes: " + likely_causes + ".";
  log.error(r.message);
  return r;
}

void damaged_checkpoint(const std::filesystem::path& checkpoint, const std::string& why) {
  throw std::runtime_error(
      checkpoint.string() + " cannot be read (" + why +
      "): it is damaged, so this run cannot continue from it. Move it away (flocsim removes "
      "nothing it cannot prove it wrote) and run again with --resume to start this case over");
}

void require_resumable(const std::filesystem::path& checkpoint, const nlohmann::json& recorded_case,
                       const nlohmann::json& current_case) {
  if (resumable_under(recorded_case, current_case)) return;
  throw input::InputError(checkpoint.string() + " belongs to a different case (" +
                          case_differences(recorded_case, current_case) +
                          "); give those fields their recorded values to continue it, or use "
                          "another --out directory");
}

}  // namespace flocsim::run
