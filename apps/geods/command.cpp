#include "command.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <regex>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/simd_level.hpp"
#include "progress_bar.hpp"

namespace geods::cli {

std::vector<std::unique_ptr<Command>>& registered_commands() {
  static std::vector<std::unique_ptr<Command>> commands;
  return commands;
}

void add_input(CLI::App& app, const std::string& name, std::string& value, const std::string& description,
               const std::string& alias) {
  if (alias.empty()) {
    app.add_option(name, value, description)->required();
    return;
  }
  CLI::Option* positional = app.add_option(name, value, description);
  CLI::Option* named = app.add_option(alias, value, "Deprecated: give " + name + " as the first argument");
  positional->excludes(named);
  app.callback([&value, name] {
    if (value.empty()) throw CLI::RequiredError(name);
  });
}

CLI::Option* add_save(CLI::App& app, std::string& path, const std::string& what, const std::string& reader) {
  return app.add_option("--save", path, "Output: " + what + " as a geods archive (" + reader + " reads it)");
}

CLI::Option* add_output(CLI::App& app, const std::string& name, std::string& path, const std::string& description,
                        io::OutputKind kind) {
  std::string accepted;
  for (const std::string& e : io::output_extensions(kind)) accepted += (accepted.empty() ? "" : ", ") + e;
  if (io::standard_output_allowed(kind)) accepted += "; - for standard output";
  return app.add_option(name, path, description + " (" + accepted + ")")
      ->check(CLI::Validator(
          [kind](std::string& value) {
            try {
              io::check_output_extension(value, kind);
            } catch (const Error& e) {
              return std::string(e.what());
            }
            return std::string();
          },
          "", "output name"));
}

CLI::Validator at_least(long long minimum) {
  return CLI::Validator(
      [minimum](std::string& value) {
        long long v = 0;
        const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
        if (ec != std::errc() || end != value.data() + value.size() || v < minimum)
          return "must be an integer >= " + std::to_string(minimum) + ", got '" + value + "'";
        return std::string();
      },
      "INT>=" + std::to_string(minimum), "at least");
}

std::string user_message(const std::string& command, const std::string& message) {
  std::string line = message.substr(0, message.find('\n'));  // the contract is one line on stderr
  if (line.starts_with(command + ": ")) line.erase(0, command.size() + 2);
  // Long fixed-notation numbers (a double through std::to_string or CLI11) become %g.
  static const std::regex long_number(R"(-?\d{13,}\.\d+|-?\d+\.\d{13,})");
  std::string out;
  auto begin = std::sregex_iterator(line.begin(), line.end(), long_number);
  std::size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    out += line.substr(last, std::size_t(it->position()) - last);
    out += format_number(std::strtod(it->str().c_str(), nullptr));
    last = std::size_t(it->position() + it->length());
  }
  return out + line.substr(last);
}

namespace {

int fail(const std::string& command, const std::string& message) {
  std::cerr << "geods " << command << ": " << user_message(command, message) << "\n";
  return 2;
}

}  // namespace

int run_cli(int argc, char** argv) {
  CLI::App app{"geods: geometric data structures for computer graphics.\n"
               "Every command reads and writes standard files; --json prints one JSON object."};
  app.set_version_flag("--version", "geods " GEODS_VERSION);
  app.require_subcommand(1);

  struct Entry {
    Command* command;
    CLI::App* sub;
  };
  std::vector<Entry> entries;
  RunContext context;
  for (auto& command : registered_commands()) {
    CLI::App* sub = app.add_subcommand(command->name(), command->summary());
    sub->add_flag("--json", context.json, "Print one JSON object instead of the summary");
    sub->add_option("--threads", context.threads, "Worker threads (default: all cores; 1: single-threaded)")
        ->check(at_least(0));
    sub->add_option("--simd", context.simd,
                    "Cap the SIMD level of the kernels: portable, avx, avx2 or avx512 (default: the best the CPU "
                    "runs, capped by GEODS_SIMD); every level gives the same results")
        ->check(CLI::IsMember({"portable", "avx", "avx2", "avx512"}));
    command->add_options(*sub);
    entries.push_back({command.get(), sub});
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const std::string where = app.get_subcommands().empty() ? "" : app.get_subcommands().front()->get_name();
    std::cerr << "geods" << (where.empty() ? "" : " " + where) << ": " << user_message(where, e.what())
              << " (see --help)\n";
    return 2;
  }

  for (const Entry& entry : entries) {
    if (!entry.sub->parsed()) continue;
    if (context.threads > 0) set_num_threads(context.threads);
    context.progress = terminal_progress_bar();
    Report report;
    int status = 0;
    try {
      // A cap, like GEODS_SIMD: a level above the CPU's best runs the best.
      if (!context.simd.empty()) set_simd_level(std::min(parse_simd_level(context.simd), best_simd_level()));
      entry.command->run(context, report);
      status = report.json.value("failed_steps", 0) > 0 ? 1 : 0;
    } catch (const Error& e) {
      return fail(entry.command->name(), e.what());
    } catch (const std::bad_alloc&) {
      return fail(entry.command->name(), "out of memory");
    } catch (const std::filesystem::filesystem_error& e) {
      return fail(entry.command->name(), e.path1().string() + ": " + e.code().message());
    } catch (const std::exception& e) {
      return fail(entry.command->name(), std::string("unexpected failure (please report it): ") + e.what());
    }
    // An output written to standard output ("-") keeps it for itself.
    std::ostream& out = io::standard_output_used() ? std::cerr : std::cout;
    if (context.json) {
      out << report.json.dump() << "\n";
    } else {
      for (const std::string& line : report.lines) out << line << "\n";
    }
    return status;
  }
  return 2;
}

}  // namespace geods::cli
