#pragma once
// The command framework of the geods CLI: one Command subclass per
// cmd_<name>.cpp, registered in one line with register_command<T>().
#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

#include "geods/core/progress.hpp"
#include "geods/io/output.hpp"
#include "report.hpp"

namespace geods::cli {

/// Options every command shares, filled in before run().
struct RunContext {
  bool json = false;
  int threads = 0;            // 0: all cores
  std::string simd;           // --simd: cap of simd_level() (core/simd_level.hpp); empty: unchanged
  ProgressCallback progress;  // a progress bar on a terminal, else empty
};

class Command {
 public:
  virtual ~Command() = default;
  virtual std::string name() const = 0;
  virtual std::string summary() const = 0;
  /// Declares the command's own options on its subcommand.
  virtual void add_options(CLI::App& app) = 0;
  /// Does the work. Bad input throws geods::Error (exit code 2).
  virtual void run(const RunContext& context, Report& report) = 0;
};

/// Declares the command's main input as the positional argument `name`
/// (the rule for every command: what the command is about is positional,
/// every other input is a named option). `alias`, e.g. "--points", keeps an
/// older option spelling working; it is deprecated. One of the two is required.
void add_input(CLI::App& app, const std::string& name, std::string& value, const std::string& description,
               const std::string& alias = "");

/// Declares --save PATH, the option of every command that builds a structure:
/// it writes `what` there as a geods archive, which `reader` reads back, e.g.
/// add_save(app, save_, "the triangulation", "Delaunay2.load").
CLI::Option* add_save(CLI::App& app, std::string& path, const std::string& what, const std::string& reader);

/// Declares an output option (e.g. "-o,--output") of the given kind: its file
/// name must have an extension `kind` can be written as (io::check_output_extension),
/// checked while the command line is parsed, before anything is read or
/// computed; the help ends with the accepted extensions. "-" is standard output
/// where the kind allows it, and the command's report then goes to standard error.
CLI::Option* add_output(CLI::App& app, const std::string& name, std::string& path, const std::string& description,
                        io::OutputKind kind);

/// A check for integer options: "must be an integer >= 1, got 0" (CLI11's
/// PositiveNumber prints its range with 300 digits).
CLI::Validator at_least(long long minimum);

/// A message as the CLI prints it: one line, without a leading "<command>: "
/// (the CLI adds "geods <command>: " itself), fixed-notation numbers of more
/// than 12 digits before or after the point shortened to %g ("1.79769e+308").
std::string user_message(const std::string& command, const std::string& message);

std::vector<std::unique_ptr<Command>>& registered_commands();

template <typename C>
bool register_command() {
  registered_commands().push_back(std::make_unique<C>());
  return true;
}

/// Runs the CLI: parses argv, dispatches, prints the report; returns the exit code
/// (0 success, 1 a failed step such as a demo step, 2 bad arguments or input).
int run_cli(int argc, char** argv);

}  // namespace geods::cli
