// flocsim query: the runs of the results database with their parameters and
// results, filtered, as an aligned table, CSV or JSON (docs/orchestrator.md).
// Safe while a sweep is running: it only reads, from a WAL snapshot.
#include <iostream>

#include "apps/flocsim/command_registry.hpp"
#include "db/results_db.hpp"
#include "engine/input/input_reader.hpp"
#include "orchestrator/report.hpp"
#include "orchestrator/terminal_table.hpp"

namespace flocsim::app {
namespace {

namespace orc = flocsim::orchestrator;

const bool registered = register_command(
    {"query", "List runs with their parameters and results (table, CSV or JSON)",
     [](CLI::App& cmd) {
       struct Options {
         std::string db_path, sweep, format = "table";
         std::vector<std::string> where, columns;
         bool all = false;
       };
       auto o = std::make_shared<Options>();
       cmd.add_option("--db", o->db_path, "Results database")->required();
       cmd.add_option("--sweep", o->sweep, "Only the runs of this sweep");
       cmd.add_option("--where,-w", o->where,
                      "Filter FIELD OP VALUE (OP: = != < <= > >=); FIELD is a column (status, an "
                      "axis, an observable, NAME_err, wall_s) or a dotted case path; repeat to AND")
           ->take_all();
       cmd.add_option("--columns,-c", o->columns,
                      "Only these columns, in this order (comma-separated or repeated), e.g. "
                      "phi,du_over_Uinf,U_over_Uinf,F")
           ->delimiter(',');
       cmd.add_flag("--all", o->all,
                    "Every column, however wide (the table otherwise fits the terminal)");
       cmd.add_option("--format,-f", o->format, "Output format")
           ->check(CLI::IsMember({"table", "csv", "json"}))
           ->capture_default_str();
       return CommandHandler([o]() -> int {
         try {
           orc::QueryOptions q;
           if (!o->sweep.empty()) q.sweep = o->sweep;
           q.format = o->format;
           q.columns = o->columns;
           // a chosen set of columns, or --all, is shown whole
           q.width = o->all || !o->columns.empty() ? 0 : orc::terminal_width();
           q.left_out = &std::cerr;
           for (const std::string& w : o->where) q.where.push_back(orc::parse_filter(w));
           db::ResultsDb db(o->db_path, db::ResultsDb::Mode::kReadOnly);  // only reads
           orc::write_query(db, q, std::cout);
           return kExitOk;
         } catch (const flocsim::input::InputError& e) {
           std::cerr << "flocsim query: " << printable(e.what()) << "\n";
           return kExitBadInput;
         } catch (const db::DbError& e) {
           std::cerr << "flocsim query: " << printable(e.what()) << "\n";
           return kExitFailure;
         }
       });
     }});

}  // namespace
}  // namespace flocsim::app
