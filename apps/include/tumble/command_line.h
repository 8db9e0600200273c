// The conventions every Tumble program keeps on its command line, as POSIX utilities, argparse and
// Go's flag package do: `--version`; exit status 2 for a usage error (0 for --help and
// --version); the defaults shown in --help; an unknown command named as such, with the commands
// there are; a value that came from an environment variable refused by the variable's name.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <string>

#ifndef TUMBLE_VERSION
#error "TUMBLE_VERSION is defined by the tumble::command_line target"
#endif

namespace tumble::cli {

inline constexpr int kUsageError = 2;

namespace detail {

inline std::string check_number(const std::string& text, bool zero_allowed) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') return text + ": not a number";
  if (zero_allowed ? !(value >= 0) : !(value > 0))
    return text + (zero_allowed ? ": must be 0 or more" : ": must be more than 0");
  return {};
}

// The option (here or in a subcommand) whose value came from its environment variable, if the
// error names it.
inline const CLI::Option* option_from_environment(const CLI::App& app, const std::string& error,
                                                  int argc, char** argv) {
  for (const CLI::Option* option : app.get_options()) {
    const std::string& variable = option->get_envname();
    if (variable.empty() || std::getenv(variable.c_str()) == nullptr) continue;
    const std::string name = option->get_name();
    if (error.find(name) == std::string::npos) continue;
    bool on_command_line = false;
    for (int i = 1; i < argc; ++i)
      on_command_line |= std::string(argv[i]).rfind(name, 0) == 0;
    if (!on_command_line) return option;
  }
  for (const CLI::App* command : app.get_subcommands({}))
    if (const CLI::Option* found = option_from_environment(*command, error, argc, argv))
      return found;
  return nullptr;
}

inline std::string command_names(const CLI::App& app) {
  std::string names;
  for (const CLI::App* command : app.get_subcommands({}))
    names += (names.empty() ? "" : ", ") + command->get_name();
  return names;
}

}  // namespace detail

// Numbers >= 0 and > 0, refused with a short message (CLI11's own print the range up to the
// largest double: 300 digits).
inline const CLI::Validator non_negative(
    [](std::string& text) { return detail::check_number(text, true); }, "NUMBER>=0");
inline const CLI::Validator positive(
    [](std::string& text) { return detail::check_number(text, false); }, "NUMBER>0");
// A file that exists, refused as "PATH: no such file".
inline const CLI::Validator existing_file(
    [](std::string& path) {
      const std::string found = CLI::ExistingFile(path);
      return found.empty() ? found : path + ": no such file";
    },
    "FILE");

// Call before adding options: --version, and defaults captured for --help.
inline void keep_conventions(CLI::App& app, const std::string& program) {
  app.set_version_flag("--version", program + " " TUMBLE_VERSION);
  app.option_defaults()->always_capture_default();
  app.name(program);
}

// Parses the command line. Returns -1 when the program should go on, else the status to exit
// with, the message printed: 0 after --help or --version, kUsageError after a usage error.
inline int parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    std::fputs(app.help("", CLI::AppFormatMode::All).c_str(), stdout);
    return 0;
  } catch (const CLI::CallForVersion&) {
    std::printf("%s\n", app.version().c_str());
    return 0;
  } catch (const CLI::ParseError& error) {
    const std::string program = app.get_name();
    std::string message = error.what();
    if (const CLI::Option* option = detail::option_from_environment(app, message, argc, argv)) {
      message = option->get_envname() + "=" + std::getenv(option->get_envname().c_str()) +
                " (the environment's value for " + option->get_name() + "): " + message;
    } else if (!app.get_subcommands({}).empty() && app.get_subcommands().empty() &&
               message.find("subcommand") != std::string::npos) {
      // No command was recognised (CLI11 says only that one is required): name the word that
      // was taken for one, or the option it does not know.
      std::string word, unknown_option;
      for (int i = 1; i < argc && word.empty() && unknown_option.empty(); ++i) {
        const std::string arg = argv[i];
        if (arg.empty() || arg[0] != '-') {
          word = arg;
          continue;
        }
        const std::string name = arg.substr(0, arg.find('='));
        const CLI::Option* option = app.get_option_no_throw(name);
        if (option == nullptr)
          unknown_option = name;
        else if (name.size() == arg.size() && option->get_expected_min() > 0)
          ++i;  // its value
      }
      message = !unknown_option.empty() ? "unknown option '" + unknown_option + "'"
                : word.empty()          ? std::string("a command is required")
                                        : "unknown command '" + word + "'";
      if (unknown_option.empty()) message += " (one of: " + detail::command_names(app) + ")";
    }
    std::fprintf(stderr, "%s: %s\nRun '%s --help' for more information.\n", program.c_str(),
                 message.c_str(), program.c_str());
    return kUsageError;
  }
}

}  // namespace tumble::cli
