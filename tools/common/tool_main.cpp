#include "tools/common/tool_main.h"

#include <sys/resource.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <memory>
#include <new>
#include <regex>

#include <tbb/global_control.h>

#include "formats/build_info.h"
#include "libcommon/core/failure.h"
#include "libcommon/core/parameter_table.h"
#include "libcommon/scene/scene.h"
#include "tools/common/scene_read_options.h"

namespace rad {

namespace {
int gThreads = 0;  // --threads; 0: every core this process may use (TBB's default)
// The largest --threads. A fixed number, not one derived from this machine's cores, so a
// command line (a Makefile's, a farm job's) means the same on every node; above the largest
// machines' hardware threads, and low enough that the threads' stacks and rad-movies' GL
// contexts (one per worker) stay within a machine's memory, where 10^8 threads aborted
// (SIGABRT) or grew without bound.
constexpr long long kMaxThreads = 1024;
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
  // --help lists the Common group first: CLI11 orders groups by their first option.
  const std::string common = parameterGroupTitle(ParameterGroup::kCommon);
  app.get_help_ptr()->group(common);
  app.get_version_ptr()->group(common);
  app.add_flag_callback(
         kPrintDefaults, [] { throw CallForDefaults(); },
         "print every option's default as one JSON object on stdout and exit")
      ->group(common);
  setGltfWarnings(tool);  // scene warnings on stderr
}

namespace {
// The options every tool has that --help lists among the Advanced ones, added last so the
// tool's own groups come first.
void addAdvancedOptions(CLI::App& app) {
  const std::string advanced = parameterGroupTitle(ParameterGroup::kAdvanced);
  // Results never depend on it (work is split by item, not by thread, and every sample seed
  // comes from ids): it only bounds the cores used, e.g. for make -j or a shared machine.
  app.add_option("--threads", gThreads, "worker threads; 0: all cores")
      ->capture_default_str()
      ->check(integerRange(0, kMaxThreads))
      ->group(advanced);
  addSceneReadOptions(app)->group(advanced);  // --max-texture-pixels
  if (CLI::Option* units = app.get_option_no_throw("--light-units")) units->group(advanced);
}
}  // namespace

int parseCommandLine(CLI::App& app, const std::string& tool, int argc, char** argv) {
  addAdvancedOptions(app);
  const nlohmann::json defaults = optionDefaults(app);  // before parsing changes the values
  try {
    app.parse(argc, argv);
  } catch (const CallForDefaults&) {
    std::cout << defaults.dump(1) << "\n";
    return finishStdout(tool, 0);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return finishStdout(tool, 0);
  } catch (const CLI::CallForVersion&) {
    std::cout << app.version() << "\n";
    return finishStdout(tool, 0);
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
  int rc = 0;
  try {
    rc = body();
  } catch (...) {
    const Failure failure = failureOf(std::current_exception());
    std::cerr << tool << ": " << oneLine(failure.message) << "\n";
    rc = int(failure.code);
  }
  return finishStdout(tool, rc);
}

int finishStdout(const std::string& tool, int rc) {
  static bool reported = false;  // rad-inspect finishes once per file: one line for all
  // std::cout shares stdout's buffer (sync_with_stdio): a failed write leaves badbit on the one
  // and the error flag on the other; the flush reports what was still buffered.
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  const int flushErrno = errno;
  if (flushed && std::cout && !std::ferror(stdout)) return rc;
  if (!reported) {
    std::cerr << tool << ": stdout: write failed";
    if (!flushed && flushErrno != 0) std::cerr << ": " << std::strerror(flushErrno);
    std::cerr << "\n";
    reported = true;
  }
  return std::max(rc, int(ExitCode::kOutput));
}

namespace {
// A CLI11 check that `accept`s the option's value, a finite number; `want` says what it must be
// in the error, `tag` in --help's type column (FLOAT:POSITIVE).
CLI::Validator finiteCheck(const std::string& want, const std::string& tag,
                           const std::function<bool(double)>& accept) {
  return CLI::Validator(
      [want, accept](std::string& input) -> std::string {
        const char* begin = input.c_str();
        char* end = nullptr;
        const double x = std::strtod(begin, &end);
        if (end == begin || *end != '\0' || !std::isfinite(x) || !accept(x))
          return input + " is not " + want;
        return "";
      },
      tag);
}
}  // namespace

CLI::Validator finiteNumber() {
  return finiteCheck("a finite number", "FINITE", [](double) { return true; });
}
CLI::Validator positiveFinite() {
  return finiteCheck("a finite number > 0", "POSITIVE", [](double x) { return x > 0.0; });
}
CLI::Validator nonNegativeFinite() {
  return finiteCheck("a finite number >= 0", "NONNEGATIVE", [](double x) { return x >= 0.0; });
}
CLI::Validator finiteRange(double lo, double hi) {
  const std::string range = "[" + numberText(lo) + ", " + numberText(hi) + "]";
  return finiteCheck("a number in " + range, range,
                     [lo, hi](double x) { return x >= lo && x <= hi; });
}

CLI::Validator integerRange(long long lo, long long hi) {
  const bool open = hi == std::numeric_limits<long long>::max();
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  const std::string want = open ? "an integer >= " + std::to_string(lo) : "an integer in " + range;
  const std::string tag = !open ? range : lo > 0 ? "POSITIVE" : "NONNEGATIVE";
  return CLI::Validator(
      [want, lo, hi](std::string& input) -> std::string {
        const char* begin = input.c_str();
        char* end = nullptr;
        errno = 0;
        const long long n = std::strtoll(begin, &end, 10);
        if (end == begin || *end != '\0' || errno == ERANGE || n < lo || n > hi)
          return input + " is not " + want;
        return "";
      },
      tag);
}
CLI::Validator positiveInteger() {
  return integerRange(1, std::numeric_limits<long long>::max());
}
CLI::Validator nonNegativeInteger() {
  return integerRange(0, std::numeric_limits<long long>::max());
}

namespace {
// The number a run of decimal digits names, or -1 when it exceeds `max` (std::stol threw
// out_of_range, an internal error, on 20 digits).
long boundedNumber(const std::string& digits, long max) {
  const size_t first = std::min(digits.find_first_not_of('0'), digits.size());
  if (digits.size() - first > 18) return -1;  // more than any long holds
  const long n = first == digits.size() ? 0 : std::stol(digits.substr(first));
  return n <= max ? n : -1;
}
}  // namespace

std::vector<int> parseFrameRange(const std::string& spec, const std::string& flag) {
  static const std::regex re(R"(^\s*(\d+)(?:\s*-\s*(\d+)(?:x(\d+))?)?\s*$)");
  constexpr long kMaxFrame = 100000000;
  std::smatch m;
  if (!std::regex_match(spec, m, re)) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": expected FIRST-LAST[xSTEP]");
  }
  const long first = boundedNumber(m[1], kMaxFrame);
  const long last = m[2].matched ? boundedNumber(m[2], kMaxFrame) : first;
  const long step = m[3].matched ? boundedNumber(m[3], kMaxFrame) : 1;
  if (first < 0 || last < 0 || step < 0)
    throw Error(ExitCode::kUsage, "",
                flag + " " + spec + ": frame numbers and step must be at most " +
                    std::to_string(kMaxFrame));
  if (last < first || step < 1) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": empty or out-of-range frame range");
  }
  std::vector<int> frames;
  for (long f = first; f <= last; f += step) frames.push_back(int(f));
  return frames;
}

std::pair<int, int> parseImageSize(const std::string& spec, const std::string& flag) {
  static const std::regex re(R"(^(\d+)x(\d+)$)");
  constexpr long kMaxSide = 16384;
  std::smatch m;
  if (!std::regex_match(spec, m, re)) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": expected WIDTHxHEIGHT");
  }
  const long w = boundedNumber(m[1], kMaxSide), h = boundedNumber(m[2], kMaxSide);
  if (w < 1 || h < 1) {
    throw Error(ExitCode::kUsage, "", flag + " " + spec + ": size must be 1..16384 per side");
  }
  return {int(w), int(h)};
}

std::string emptyFramesWarning(const std::string& tool, size_t empty, int firstEmpty, size_t frames,
                               const Camera& lens) {
  if (empty == 0) return "";
  const std::string camera = lens.name.empty() ? "the camera" : "camera '" + lens.name + "'";
  const std::string zfar = lens.zfar > 0.0 ? numberText(lens.zfar) : std::string("infinite");
  return tool + ": warning: " + std::to_string(empty) + " of " + std::to_string(frames) +
         " frames show no surface (the first: frame " + std::to_string(firstEmpty) +
         "), so they are black: the scene lies outside " + camera + "'s view or clip planes " +
         "(znear " + numberText(lens.znear) + ", zfar " + zfar + ")\n";
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
    : label_(std::move(label)),
      total_(total),
      active_(stderrIsTerminal() && total > 0),
      logging_(!stderrIsTerminal() && total > 0),
      lastLog_(std::chrono::steady_clock::now()) {}

void Progress::advance(long n) {
  count_ += n;
  if (logging_) log();
  if (!active_) return;
  int pct = int(100 * count_ / total_);
  if (pct == lastPercent_) return;
  lastPercent_ = pct;
  int filled = pct * 30 / 100;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%% (%ld/%ld)", label_.c_str(), filled,
               "##############################", 30 - filled, "", pct, count_, total_);
  std::fflush(stderr);
}

void Progress::log() {
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - lastLog_).count() < kLogSeconds || count_ >= total_)
    return;
  lastLog_ = now;
  std::fprintf(stderr, "%s: %ld/%ld (%d %%)\n", label_.c_str(), count_, total_,
               int(100 * count_ / total_));
}

void Progress::done() {
  if (active_ && lastPercent_ >= 0) std::fprintf(stderr, "\n");
  active_ = false;
  logging_ = false;
}

Progress::~Progress() {
  done();
}

}  // namespace rad
