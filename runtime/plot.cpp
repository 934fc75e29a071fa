#include "plot.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace quadgen::runtime {

namespace {
// gnuplot's enhanced text reads _ and ^ as sub- and superscripts; labels are plain text.
std::string plain(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '_' || c == '^' || c == '@' || c == '{' || c == '}') out += "\\";
    if (c == '\'') out += '\'';
    out += c;
  }
  return out;
}
}  // namespace

bool plot_svg(const std::string& path, const std::string& title, const std::vector<Panel>& panels, std::string* error) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("quadgen_plot_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string tmp_svg = path + ".tmp." + std::to_string(getpid());
  std::ostringstream script;
  const int height = 260 * static_cast<int>(panels.size()) + 40;
  script << "set terminal svg size 900," << height << " dynamic enhanced font 'sans,11'\n"
         << "set output '" << tmp_svg << "'\n"
         << "set multiplot layout " << panels.size() << ",1 title '" << plain(title) << "'\n"
         << "set grid\nset key outside right\n";
  int file_no = 0;
  for (const Panel& p : panels) {
    script << "set title '" << plain(p.title) << "'\nset xlabel '" << plain(p.xlabel) << "'\nset ylabel '"
           << plain(p.ylabel) << "'\nplot ";
    for (size_t s = 0; s < p.series.size(); ++s) {
      const fs::path data = dir / ("d" + std::to_string(file_no++) + ".dat");
      std::ofstream out(data);
      out.precision(10);
      for (size_t i = 0; i < p.series[s].x.size(); ++i) out << p.series[s].x[i] << ' ' << p.series[s].y[i] << '\n';
      script << (s ? ", " : "") << "'" << data.string() << "' using 1:2 with " << (p.series[s].points ? "points pt 7 ps 0.5" : "lines lw 1.5")
             << " title '" << plain(p.series[s].label) << "'";
    }
    script << "\n";
  }
  script << "unset multiplot\n";
  const fs::path script_path = dir / "plot.gp";
  std::ofstream(script_path) << script.str();
  const std::string cmd = "gnuplot " + script_path.string() + " 2> " + (dir / "err.txt").string();
  const int rc = std::system(cmd.c_str());
  bool ok = rc == 0 && fs::exists(tmp_svg);
  if (ok) {
    fs::rename(tmp_svg, path);
  } else if (error) {
    std::ifstream err(dir / "err.txt");
    std::string msg((std::istreambuf_iterator<char>(err)), {});
    *error = rc == 127 * 256 || msg.find("not found") != std::string::npos ? "gnuplot is not installed" : "gnuplot failed: " + msg.substr(0, 200);
    std::remove(tmp_svg.c_str());
  }
  fs::remove_all(dir);
  return ok;
}

}  // namespace quadgen::runtime
