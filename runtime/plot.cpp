#include "runtime/plot.hpp"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include "output/ascii.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"

extern char** environ;

namespace quadgen::runtime {
namespace {

using output::gnuplot_string;

void write_number(std::ostream& os, double v) {
  if (std::isfinite(v)) os << v;
  else os << "NaN";  // gnuplot skips it; "inf" or "nan" as printed by iostreams are not numbers to it
}

bool has_finite_point(const Series& s) {
  for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
    if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) return true;
  return false;
}

// One file descriptor pair end, closed when it goes out of scope.
struct Fd {
  int fd = -1;
  ~Fd() { reset(); }
  void reset() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

struct GnuplotRun {
  int status = -1;
  std::string out, err;
  std::string failure;  // set when gnuplot could not be run at all
};

// Runs gnuplot with `script` on standard input, collecting standard output and error. No
// shell is involved. Sockets instead of pipes: send() with MSG_NOSIGNAL cannot raise SIGPIPE
// in this process if gnuplot exits before reading everything.
GnuplotRun run_gnuplot(const std::string& script) {
  GnuplotRun run;
  int in[2], out[2], err[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, in) || socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, out) ||
      socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, err)) {
    run.failure = std::string("cannot start gnuplot: ") + std::strerror(errno);
    return run;
  }
  Fd in_r{in[0]}, in_w{in[1]}, out_r{out[0]}, out_w{out[1]}, err_r{err[0]}, err_w{err[1]};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in_r.fd, 0);
  posix_spawn_file_actions_adddup2(&actions, out_w.fd, 1);
  posix_spawn_file_actions_adddup2(&actions, err_w.fd, 2);
  char arg0[] = "gnuplot";
  char* argv[] = {arg0, nullptr};
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    run.failure = rc == ENOENT ? "gnuplot is not installed" : std::string("cannot start gnuplot: ") + std::strerror(rc);
    return run;
  }
  in_r.reset();
  out_w.reset();
  err_w.reset();
  size_t sent = 0;
  char buf[1 << 16];
  while (out_r.fd >= 0 || err_r.fd >= 0) {
    pollfd fds[3] = {{in_w.fd, POLLOUT, 0}, {out_r.fd, POLLIN, 0}, {err_r.fd, POLLIN, 0}};
    if (::poll(fds, 3, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (in_w.fd >= 0 && (fds[0].revents & (POLLOUT | POLLERR | POLLHUP))) {
      const ssize_t n = ::send(in_w.fd, script.data() + sent, std::min<size_t>(script.size() - sent, sizeof buf), MSG_NOSIGNAL);
      if (n > 0) sent += static_cast<size_t>(n);
      if (n < 0 && errno != EINTR && errno != EAGAIN) in_w.reset();  // gnuplot stopped reading
      if (sent == script.size()) in_w.reset();                        // end of script
    }
    for (auto [k, fd, sink] : {std::tuple{1, &out_r, &run.out}, std::tuple{2, &err_r, &run.err}}) {
      if (fd->fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t n = ::read(fd->fd, buf, sizeof buf);
      if (n > 0) sink->append(buf, static_cast<size_t>(n));
      else if (n == 0 || errno != EINTR) fd->reset();
    }
  }
  while (::waitpid(pid, &run.status, 0) < 0 && errno == EINTR) {
  }
  return run;
}

// A character reference at tag[at] == '&', as an HTML parser reads one (the SVG is also
// inlined into report.html): "&#106;", "&#x6a", without ';' too, or one of XML's five named
// ones. Sets `end` to its last character and returns the character's code; -1 for a lone '&';
// -2 for any other named reference: HTML knows two thousand ("&colon;"), so one is refused.
long character_reference(const std::string& tag, size_t at, size_t* end) {
  static const std::map<std::string, char> named = {{"amp", '&'}, {"lt", '<'}, {"gt", '>'}, {"quot", '"'}, {"apos", '\''}};
  size_t k = at + 1;
  if (k < tag.size() && tag[k] == '#') {
    const bool hex = k + 1 < tag.size() && tag[k + 1] == 'x';
    const size_t first = k + (hex ? 2 : 1);
    const auto digit = [hex](char d) -> long {  // the tag is lower case
      if (d >= '0' && d <= '9') return d - '0';
      return hex && d >= 'a' && d <= 'f' ? d - 'a' + 10 : -1;
    };
    long code = 0;
    for (k = first; k < tag.size() && digit(tag[k]) >= 0; ++k) code = std::min(code * (hex ? 16 : 10) + digit(tag[k]), 0x110000L);
    if (k == first) return -1;
    *end = k < tag.size() && tag[k] == ';' ? k : k - 1;
    return code;
  }
  while (k < tag.size() && std::isalnum(static_cast<unsigned char>(tag[k]))) ++k;
  if (k == at + 1) return -1;
  const auto it = named.find(tag.substr(at + 1, k - at - 1));
  if (it == named.end() || k >= tag.size() || tag[k] != ';') return -2;
  *end = k;
  return it->second;
}

// A tag (lower case) as a browser reads a URL in it: character references decoded (the XML or
// HTML parser does that before the URL parser sees the value) and the ASCII tabs, line breaks
// and other controls dropped, which the URL parser drops from a scheme ("java&#9;script:").
// Nothing when the tag holds a named reference beyond XML's five.
std::optional<std::string> as_browser_reads(const std::string& tag) {
  std::string out;
  for (size_t i = 0; i < tag.size(); ++i) {
    char c = tag[i];
    size_t end = i;
    if (const long code = c == '&' ? character_reference(tag, i, &end) : -1; code == -2) {
      return std::nullopt;
    } else if (code >= 0) {
      c = code < 128 ? output::ascii_lower(static_cast<char>(code)) : '?';
      i = end;
    }
    if (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f) out += c;
  }
  return out;
}

}  // namespace

// Tags are read with their quoted attribute values whole (XML allows a raw '>' inside one), in
// one pass; every '<' of text is escaped by gnuplot, so text cannot open a tag.
bool whole_inert_svg(const std::string& svg) {
  const size_t end = svg.find_last_not_of(" \n\r\t");
  if (svg.find("<svg") == std::string::npos || end == std::string::npos || end < 5 || svg.compare(end - 5, 6, "</svg>") != 0)
    return false;
  // Elements and attributes that carry a document or script of their own; gnuplot writes none.
  static const char* const kForeign[] = {"<script", ":script", "<iframe", "<foreignobject", "<object", "<embed", "srcdoc"};
  const auto refused = [](const std::string& tag) {
    const std::optional<std::string> read = as_browser_reads(tag);
    if (!read) return true;
    for (const std::string& form : {tag, *read}) {  // as written, and with its references decoded
      for (const char* foreign : kForeign)
        if (form.find(foreign) != std::string::npos) return true;
      if (form.find("javascript:") != std::string::npos || form.find("vbscript:") != std::string::npos) return true;
      for (size_t on = form.find("on"); on != std::string::npos; on = form.find("on", on + 1)) {  // an event handler
        // An attribute's name starts after anything a name cannot hold: a blank, '/', a quote.
        const char before = on == 0 ? ' ' : form[on - 1];
        if (std::isalnum(static_cast<unsigned char>(before)) || std::string("_:.-").find(before) != std::string::npos) continue;
        size_t k = on + 2;
        while (k < form.size() && std::isalpha(static_cast<unsigned char>(form[k]))) ++k;
        while (k < form.size() && std::isspace(static_cast<unsigned char>(form[k]))) ++k;
        if (k > on + 2 && k < form.size() && form[k] == '=') return true;
      }
    }
    return false;
  };
  std::string tag;
  char quote = 0;
  bool in_tag = false;
  for (const char raw : svg) {
    const char c = output::ascii_lower(raw);
    if (!in_tag) {
      if (c != '<') continue;
      in_tag = true;
      tag.clear();
    }
    tag += c;
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      in_tag = false;
      if (refused(tag)) return false;
    }
  }
  return !in_tag;
}

Series decimated(const Series& s) {
  const size_t n = std::min(s.x.size(), s.y.size());
  if (n <= kMaxPlotPointsPerSeries) return s;
  Series d = s;  // its label, style, colour and marker (a thinned series lost its colour: helper-107)
  d.x.clear();
  d.y.clear();
  const size_t buckets = kMaxPlotPointsPerSeries / 2;
  for (size_t b = 0; b < buckets; ++b) {
    const size_t lo = b * n / buckets, hi = (b + 1) * n / buckets;
    size_t imin = lo, imax = lo;
    for (size_t i = lo; i < hi; ++i) {
      if (s.y[i] < s.y[imin]) imin = i;
      if (s.y[i] > s.y[imax]) imax = i;
    }
    for (size_t i : {std::min(imin, imax), std::max(imin, imax)}) {
      d.x.push_back(s.x[i]);
      d.y.push_back(s.y[i]);
      if (imin == imax) break;
    }
  }
  return d;
}

namespace {
// "#rrggbb" and nothing else reaches the script as a colour.
bool is_rgb(const std::string& c) {
  if (c.size() != 7 || c[0] != '#') return false;
  for (size_t i = 1; i < 7; ++i)
    if (!std::isxdigit(static_cast<unsigned char>(c[i]))) return false;
  return true;
}
}  // namespace

std::string gnuplot_script(const std::string& title, const std::vector<Panel>& panels) {
  std::ostringstream script;
  script.precision(10);
  const int height = 260 * static_cast<int>(panels.size()) + 40;
  script << "set encoding utf8\n"
         << "set terminal svg size 900," << height << " dynamic noenhanced font 'sans,11'\n"
         << "set multiplot layout " << panels.size() << ",1 title " << gnuplot_string(title) << " noenhanced\n"
         << "set grid\nset key outside right noenhanced\n"
         // Four significant digits on the ticks: gnuplot's default wrote 1.05e-6 and 1.1e-6 both
         // as 0.0000011 (a user trial, helper-106).
         << "set format x '%.4g'\nset format y '%.4g'\n";
  int block = 0;
  for (const Panel& p : panels) {
    script << "set title " << gnuplot_string(p.title) << " noenhanced\n"
           << "set xlabel " << gnuplot_string(output::unit_for_reading(p.xlabel)) << " noenhanced\n"
           << "set ylabel " << gnuplot_string(output::unit_for_reading(p.ylabel)) << " noenhanced\n";
    std::ostringstream plot;
    for (const Series& full : p.series) {
      const Series s = decimated(full);
      if (!has_finite_point(s)) continue;  // gnuplot refuses a series whose every value is undefined
      const std::string name = "$d" + std::to_string(block++);
      script << name << " << EOD\n";
      for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
        write_number(script, s.x[i]);
        script << ' ';
        write_number(script, s.y[i]);
        script << '\n';
      }
      script << "EOD\n";
      plot << (plot.tellp() > 0 ? ", " : "") << name << " using 1:2 with "
           << (s.points ? "points pt " + std::to_string(std::clamp(s.marker, 1, 15)) + " ps 0.5" : std::string("lines lw 1.5"));
      if (is_rgb(s.color)) plot << " lc rgb '" << s.color << "'";
      plot << " title " << gnuplot_string(s.label) << " noenhanced";
    }
    script << "unset arrow\nunset label\n";
    for (const auto& [x, text] : p.labels)
      if (std::isfinite(x)) {
        script << "set label " << gnuplot_string(text) << " at first ";
        write_number(script, x);
        script << ", graph 0.93 offset 0.5,0 noenhanced front font ',9'\n";
      }
    for (double m : p.marks)
      if (std::isfinite(m)) {
        script << "set arrow from ";
        write_number(script, m);
        script << ", graph 0 to ";
        write_number(script, m);
        script << ", graph 1 nohead dt 2 lw 1.5 lc rgb '#555555'\n";
      }
    // A panel without data still gets its axes, so the layout of the figure stays the same.
    script << "plot " << (plot.tellp() > 0 ? plot.str() : "[0:1][0:1] -1 notitle") << "\n";
  }
  script << "unset multiplot\n";
  return script.str();
}

bool render_svg(const std::string& title, const std::vector<Panel>& panels, std::string* svg, std::string* error) {
  const GnuplotRun run = run_gnuplot(gnuplot_script(title, panels));
  std::string why, mended;
  if (!run.failure.empty()) why = run.failure;
  else if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0)
    why = "gnuplot failed: " + output::printable(run.err.substr(0, 300));
  else {
    mended = output::gnuplot_svg_tooltips_mended(run.out);
    if (!whole_inert_svg(mended))  // checked as it is written
      why = "gnuplot returned no complete SVG document, or one with script in a tag";
  }
  if (!why.empty()) {
    if (error) *error = why;
    return false;
  }
  *svg = std::move(mended);
  return true;
}

std::string panels_csv(const std::string& title, const std::vector<Panel>& panels) {
  std::string out = "plot,panel,x_label,y_label,series,x,y\n";
  // Each number as the shortest text that reads back as it (0.1, not 0.10000000000000001).
  const auto field = [&](double v) { return std::isfinite(v) ? output::full_number(v) : std::string(); };
  const std::string plot = output::csv_field(title);
  for (const auto& p : panels) {
    const std::string prefix = plot + "," + output::csv_field(p.title) + "," + output::csv_field(p.xlabel) + "," +
                               output::csv_field(p.ylabel) + ",";
    for (const auto& s : p.series) {
      const std::string lead = prefix + output::csv_field(s.label) + ",";
      for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) out += lead + field(s.x[i]) + "," + field(s.y[i]) + "\n";
    }
  }
  return out;
}

}  // namespace quadgen::runtime
