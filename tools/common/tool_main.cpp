#include "tools/common/tool_main.h"

#include <sys/resource.h>

#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <memory>
#include <new>
#include <regex>

#include <tbb/global_control.h>

#include "formats/build_info.h"

namespace rad {

namespace {
int gThreads = 0;  // --threads; 0: every core this process may use (TBB's default)
std::unique_ptr<tbb::global_control> gThreadLimit;

constexpr const char* kPrintDefaults = "--print-defaults";

// Thrown by --print-defaults' callback, which CLI11 runs before it checks required options
// (like --help), so `rad-global --print-defaults` needs no scene.
class CallForDefaults : public CLI::Success {
 public:
  CallForDefaults()
      : CLI::Success("CallForDefaults", "print the defaults and exit", CLI::ExitCodes::Success) {}
};

bool isNumberType(const std::string& typeName) {
  const std::string base = typeName.substr(0, typeName.find(':'));  // "FLOAT:POSITIVE"
  return base == "INT" || base == "UINT" || base == "FLOAT" || base == "NUMBER";
}

// The default CLI11 would show in --help if it were captured: the bound variable's value now,
// read without changing what --help shows.
std::string boundDefault(CLI::Option& opt) {
  const std::string shown = opt.get_default_str();
  opt.capture_default_str();
  const std::string value = opt.get_default_str();
  opt.default_str(shown);
  return value;
}

nlohmann::json defaultValue(CLI::Option& opt) {
  const std::string text = boundDefault(opt);
  if (opt.get_items_expected_max() == 0) return text == "true" || text == "1";  // a flag
  if (text.empty() || text == "[]") return nullptr;  // no default, or an empty list
  if (isNumberType(opt.get_type_name())) {
    nlohmann::json number = nlohmann::json::parse(text, nullptr, false);
    if (number.is_number()) return number;
  }
  return text;
}
}  // namespace

nlohmann::json optionDefaults(CLI::App& app) {
  nlohmann::json out = nlohmann::json::object();
  for (CLI::Option* opt : app.get_options()) {
    if (opt == app.get_help_ptr() || opt == app.get_version_ptr()) continue;
    const std::vector<std::string>& names = opt->get_lnames();
    if (names.empty() || "--" + names.front() == kPrintDefaults) continue;  // positionals too
    out[names.front()] = defaultValue(*opt);
  }
  return out;
}

void setUpApp(CLI::App& app, const std::string& tool, const std::string& example) {
  app.name(tool);
  app.set_version_flag("--version", std::string(tool) + " " RAD_VERSION " (" + gitRevision() + ")");
  app.footer(std::string("Example:\n  ") + example + "\n\n" + exitCodeHelp());
  app.get_formatter()->column_width(34);
  // Results never depend on it (work is split by item, not by thread, and every sample seed
  // comes from ids): it only bounds the cores used, e.g. for make -j or a shared machine.
  app.add_option("--threads", gThreads, "worker threads; 0: all cores")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_flag_callback(
      kPrintDefaults, [] { throw CallForDefaults(); },
      "print every option's default as one JSON object on stdout and exit");
}

int parseCommandLine(CLI::App& app, const std::string& tool, int argc, char** argv) {
  const nlohmann::json defaults = optionDefaults(app);  // before parsing changes the values
  try {
    app.parse(argc, argv);
  } catch (const CallForDefaults&) {
    std::cout << defaults.dump(1) << "\n";
    return 0;
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::CallForVersion&) {
    std::cout << app.version() << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    std::cerr << tool << ": " << e.what() << " (try --help)\n";
    return int(ExitCode::kUsage);
  }
  if (gThreads > 0)
    gThreadLimit = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, size_t(gThreads));
  return -1;
}

namespace {
// An error line is at most this many bytes: a safety net for messages that quote input (each
// source cuts its quotes at 120 bytes; a failed data URI was once echoed whole, 12.5 KB).
constexpr size_t kMaxErrorLine = 1000;

// Messages from libraries (OpenEXR, tinygltf) may span lines; ours are one line by contract.
std::string oneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  if (s.size() > kMaxErrorLine) {
    size_t end = kMaxErrorLine;  // cut at a UTF-8 character boundary
    while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
    s = s.substr(0, end) + "…";
  }
  return s;
}
}  // namespace

int runTool(const std::string& tool, const std::function<int()>& body) {
  try {
    return body();
  } catch (const Error& e) {
    std::cerr << tool << ": " << oneLine(e.what()) << "\n";
    return int(e.code());
  } catch (const std::bad_alloc&) {
    std::cerr << tool << ": out of memory\n";
    return int(ExitCode::kEnvironment);
  } catch (const std::exception& e) {
    std::cerr << tool << ": internal error: " << oneLine(e.what()) << "\n";
    return int(ExitCode::kInternal);
  }
}

std::vector<int> parseFrameRange(const std::string& spec, const std::string& flag) {
  static const std::regex re(R"(^\s*(\d+)(?:\s*-\s*(\d+)(?:x(\d+))?)?\s*$)");
  std::smatch m;
  if (!std::regex_match(spec, m, re)) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": expected FIRST-LAST[xSTEP]");
  }
  long first = std::stol(m[1]);
  long last = m[2].matched ? std::stol(m[2]) : first;
  long step = m[3].matched ? std::stol(m[3]) : 1;
  if (last < first || step < 1 || last > 100000000) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": empty or out-of-range frame range");
  }
  std::vector<int> frames;
  for (long f = first; f <= last; f += step) frames.push_back(int(f));
  return frames;
}

std::pair<int, int> parseImageSize(const std::string& spec, const std::string& flag) {
  static const std::regex re(R"(^(\d+)x(\d+)$)");
  std::smatch m;
  if (!std::regex_match(spec, m, re)) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": expected WIDTHxHEIGHT");
  }
  long w = std::stol(m[1]), h = std::stol(m[2]);
  if (w < 1 || h < 1 || w > 16384 || h > 16384) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": size must be 1..16384 per side");
  }
  return {int(w), int(h)};
}

double peakMemoryMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

bool stderrIsTerminal() {
  return isatty(STDERR_FILENO) != 0;
}

Progress::Progress(std::string label, long total)
    : label_(std::move(label)), total_(total), active_(stderrIsTerminal() && total > 0) {}

void Progress::advance(long n) {
  count_ += n;
  if (!active_) return;
  int pct = int(100 * count_ / total_);
  if (pct == lastPercent_) return;
  lastPercent_ = pct;
  int filled = pct * 30 / 100;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%% (%ld/%ld)", label_.c_str(), filled,
               "##############################", 30 - filled, "", pct, count_, total_);
  std::fflush(stderr);
}

void Progress::done() {
  if (active_ && lastPercent_ >= 0) std::fprintf(stderr, "\n");
  active_ = false;
}

Progress::~Progress() {
  done();
}

}  // namespace rad
