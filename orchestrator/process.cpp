#include "orchestrator/process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <cerrno>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace flocsim::orchestrator {

std::string host_name() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "localhost";
  return buf;
}

namespace {
// Fields of /proc/PID/stat after the command name: state is [0], starttime [19].
std::vector<std::string> proc_stat_fields(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!f || !std::getline(f, line)) return {};
  const auto close = line.rfind(')');
  if (close == std::string::npos) return {};
  std::istringstream rest(line.substr(close + 1));
  std::vector<std::string> fields;
  std::string w;
  while (rest >> w) fields.push_back(w);
  return fields;
}
}  // namespace

std::string process_start_time(pid_t pid) {
  const auto fields = proc_stat_fields(pid);
  return fields.size() > 19 ? fields[19] : std::string();
}

bool process_alive(pid_t pid, const std::string& start_time) {
  if (pid <= 0) return false;
  if (kill(pid, 0) != 0 && errno != EPERM) return false;
  const auto fields = proc_stat_fields(pid);
  if (fields.empty()) return true;  // no /proc: kill(0) is all we know
  if (fields[0] == "Z" || fields[0] == "X") return false;
  if (!start_time.empty() && fields.size() > 19 && fields[19] != start_time) return false;
  return true;
}

pid_t spawn(const std::vector<std::string>& argv, const std::string& log_file,
            const std::vector<std::pair<std::string, std::string>>& environment) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  // The worker's environment, built before fork (setenv is not safe between
  // fork and exec): this process's, with `environment` replacing or adding.
  std::vector<std::string> env_text;
  for (char** e = environ; *e; ++e) {
    const std::string entry(*e);
    bool replaced = false;
    for (const auto& [name, value] : environment)
      replaced = replaced || entry.rfind(name + "=", 0) == 0;
    if (!replaced) env_text.push_back(entry);
  }
  for (const auto& [name, value] : environment) env_text.push_back(name + "=" + value);
  std::vector<char*> envp;
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  const pid_t parent = getpid();
  const int log_fd = open(log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0)
    throw std::runtime_error("cannot open worker log " + log_file + ": " + std::strerror(errno));
  const pid_t pid = fork();
  if (pid < 0) {
    close(log_fd);
    throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  }
  if (pid == 0) {
    setpgid(0, 0);
#ifdef __linux__
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
#endif
    // Default signal dispositions and an empty mask for the worker.
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, 0);
    dup2(log_fd, 1);
    dup2(log_fd, 2);
    execve(args[0], args.data(), envp.data());
    const char msg[] = "flocsim sweep: cannot execute the worker program\n";
    (void)!write(2, msg, sizeof msg - 1);
    _exit(127);
  }
  (void)parent;
  close(log_fd);
  return pid;
}

std::optional<db::Heartbeat> read_progress(const std::string& run_dir) {
  const std::string file = run_dir + "/progress.json";
  struct stat st {};
  if (stat(file.c_str(), &st) != 0) return std::nullopt;
  db::Heartbeat hb;
  hb.at = static_cast<double>(st.st_mtim.tv_sec) + 1e-9 * static_cast<double>(st.st_mtim.tv_nsec);
  std::ifstream f(file);
  try {
    const nlohmann::json p = nlohmann::json::parse(f);
    auto num = [&](const char* k) -> std::optional<double> {
      if (p.contains(k) && p[k].is_number()) return p[k].get<double>();
      return std::nullopt;
    };
    auto integer = [&](const char* k) -> std::optional<std::int64_t> {
      if (p.contains(k) && p[k].is_number()) return static_cast<std::int64_t>(p[k].get<double>());
      return std::nullopt;
    };
    hb.fraction = num("fraction");
    hb.eta_s = num("eta_s");
    hb.mlups = num("mlups");
    hb.step = integer("step");
    hb.steps_total = integer("steps_total");
    if (auto at = num("updated_at")) hb.at = std::max(hb.at, *at);
  } catch (const std::exception&) {
    // The mtime alone still proves the worker is alive.
  }
  return hb;
}

RunStage read_run_stage(const std::string& run_dir) {
  RunStage s;
  std::ifstream f(run_dir + "/progress.json");
  if (!f) return s;
  try {
    const nlohmann::json p = nlohmann::json::parse(f);
    if (p.contains("stage") && p["stage"].is_string()) s.stage = p["stage"].get<std::string>();
    if (p.contains("time") && p["time"].is_number()) s.time = p["time"].get<double>();
    if (p.contains("time_total") && p["time_total"].is_number())
      s.time_total = p["time_total"].get<double>();
    if (p.contains("time_unit") && p["time_unit"].is_string())
      s.time_unit = p["time_unit"].get<std::string>();
  } catch (const std::exception&) {
    // a file being replaced, or an older worker's: the stage is unknown
  }
  return s;
}

ResultRead read_result(const std::string& run_dir, const std::string& run_id) {
  const std::string file = run_dir + "/result.json";
  std::ifstream f(file);
  if (!f) return {std::nullopt, file + " does not exist"};
  std::stringstream text;
  text << f.rdbuf();
  nlohmann::json r;
  try {
    r = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    return {std::nullopt, file + " is not valid JSON (truncated? bad syntax at byte " +
                              std::to_string(e.byte) + ")"};
  }
  if (!r.is_object()) return {std::nullopt, file + " does not hold a JSON object"};
  if (r.value("status", nlohmann::json()) != "completed")
    return {std::nullopt, file + ": \"status\" is not \"completed\""};
  if (!r.contains("observables") || !r["observables"].is_object())
    return {std::nullopt, file + ": \"observables\" is missing or not an object"};
  if (!r.contains("case") || !r["case"].is_object())
    return {std::nullopt, file + ": \"case\" is missing or not an object"};
  db::ResultRecord rec;
  rec.run_id = run_id;
  rec.result_json = r.dump();
  rec.flocsim_version = r.value("flocsim_version", nlohmann::json("")).is_string()
                            ? r.value("flocsim_version", std::string())
                            : r["flocsim_version"].dump();
  if (r.contains("completed_at"))
    rec.completed_at = r["completed_at"].is_string() ? r["completed_at"].get<std::string>()
                                                     : r["completed_at"].dump();
  if (r.contains("cost") && r["cost"].is_object()) {
    const auto& c = r["cost"];
    if (c.contains("wall_s") && c["wall_s"].is_number()) rec.wall_s = c["wall_s"].get<double>();
    if (c.contains("MLUPS") && c["MLUPS"].is_number()) rec.mlups = c["MLUPS"].get<double>();
    if (c.contains("steps") && c["steps"].is_number())
      rec.steps = static_cast<std::int64_t>(c["steps"].get<double>());
  }
  for (auto it = r["observables"].begin(); it != r["observables"].end(); ++it) {
    const auto& v = it.value();
    if (it.key() == "window") {
      rec.window_json = v.dump();
    } else if (v.is_number()) {
      rec.observables.push_back({it.key(), v.get<double>(), std::nullopt});
    } else if (v.is_object() && v.contains("mean") && v["mean"].is_number()) {
      std::optional<double> err;
      if (v.contains("error") && v["error"].is_number()) err = v["error"].get<double>();
      rec.observables.push_back({it.key(), v["mean"].get<double>(), err});
    }
    // Other values (arrays, strings) stay in result_json only.
  }
  return {std::move(rec), ""};
}

std::string tail_of_file(const std::string& filename, std::size_t max_chars) {
  std::ifstream f(filename, std::ios::binary);
  if (!f) return "";
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  const std::streamoff from = size > static_cast<std::streamoff>(max_chars)
                                  ? size - static_cast<std::streamoff>(max_chars)
                                  : 0;
  f.seekg(from);
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (from > 0) {
    const auto nl = text.find('\n');
    if (nl != std::string::npos) text = text.substr(nl + 1);
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

std::string signal_name(int sig) {
  const char* d = strsignal(sig);
  std::string name;
  switch (sig) {
    case SIGKILL:
      name = "SIGKILL";
      break;
    case SIGTERM:
      name = "SIGTERM";
      break;
    case SIGINT:
      name = "SIGINT";
      break;
    case SIGSEGV:
      name = "SIGSEGV";
      break;
    case SIGABRT:
      name = "SIGABRT";
      break;
    case SIGBUS:
      name = "SIGBUS";
      break;
    case SIGFPE:
      name = "SIGFPE";
      break;
    default:
      name = "signal " + std::to_string(sig);
  }
  return d ? name + " (" + d + ")" : name;
}

}  // namespace flocsim::orchestrator
