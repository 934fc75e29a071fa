#include "flight_log.hpp"

#include "attitude.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

namespace quadgen::runtime {

int CsvTable::column(const std::string& name) const { return index_in(columns, name); }

std::vector<double> CsvTable::values(const std::string& name) const {
  const int c = column(name);
  if (c < 0) throw LogError(path + ": no column '" + name + "'");
  std::vector<double> v;
  for (const auto& r : rows) v.push_back(r[c]);
  return v;
}

CsvTable parse_csv(const std::string& text, const std::string& path) {
  CsvTable t;
  t.path = path;
  std::istringstream in(text);
  std::string line;
  int lineno = 0;
  auto fail = [&](const std::string& what) { throw LogError(path + ":" + std::to_string(lineno) + ": " + what); };
  auto split = [](const std::string& s) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream ss(s);
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (!s.empty() && s.back() == ',') cells.push_back("");
    return cells;
  };
  while (std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (t.columns.empty()) {
      t.columns = split(line);
      std::set<std::string> seen;
      for (const auto& c : t.columns)
        if (!seen.insert(c).second) fail("duplicate column '" + c + "'");
      continue;
    }
    const auto cells = split(line);
    if (cells.size() != t.columns.size())
      fail("expected " + std::to_string(t.columns.size()) + " values, got " + std::to_string(cells.size()));
    std::vector<double> row;
    for (size_t i = 0; i < cells.size(); ++i) {
      char* end = nullptr;
      const double v = std::strtod(cells[i].c_str(), &end);
      if (cells[i].empty() || end == cells[i].c_str() || *end != '\0')
        fail("column '" + t.columns[i] + "': expected a number, got '" + cells[i] + "'");
      row.push_back(v);
    }
    t.rows.push_back(std::move(row));
  }
  if (t.columns.empty()) throw LogError(path + ":1: empty log (expected a header line)");
  return t;
}

CsvTable read_csv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw LogError(path + ": cannot open log");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_csv(ss.str(), path);
}

void validate_canonical(const CsvTable& log, const std::vector<std::string>& rotors) {
  if (log.column("t") < 0) throw LogError(log.path + ":1: missing column 't'");
  std::set<std::string> known(rotors.begin(), rotors.end());
  for (const auto& c : log.columns)
    if (c.rfind("u_", 0) == 0 && !known.count(c.substr(2))) {
      std::string list;
      for (const auto& r : rotors) list += (list.empty() ? "" : ", ") + r;
      throw LogError(log.path + ":1: column '" + c + "' names no rotor of this vehicle (rotors: " + list + ")");
    }
  for (const auto& r : rotors)
    if (log.column("u_" + r) < 0) throw LogError(log.path + ":1: missing column 'u_" + r + "'");
  if (log.rows.size() < 2) throw LogError(log.path + ": too few samples (" + std::to_string(log.rows.size()) + ")");
  const int tc = log.column("t");
  for (size_t i = 0; i < log.rows.size(); ++i) {
    for (size_t c = 0; c < log.columns.size(); ++c)
      if (!std::isfinite(log.rows[i][c]))
        throw LogError(log.path + ":" + std::to_string(i + 2) + ": column '" + log.columns[c] + "' is not finite");
    if (i > 0 && !(log.rows[i][tc] > log.rows[i - 1][tc]))
      throw LogError(log.path + ":" + std::to_string(i + 2) + ": time not strictly increasing (" +
                     std::to_string(log.rows[i - 1][tc]) + " then " + std::to_string(log.rows[i][tc]) + ")");
  }
}

std::string trajectory_csv(const DynamicModel& m, const Trajectory& tr, const InputFunction& u,
                           const std::vector<std::string>& rotors) {
  std::ostringstream os;
  os.precision(10);
  os << "t";
  for (const auto& r : rotors) os << ",u_" << r;
  os << ",x,y,z,qw,qx,qy,qz,phi,theta,psi,vx,vy,vz,p,q,r";
  for (int i = 13; i < m.num_states(); ++i) os << "," << m.state_names()[i];
  os << "\n";
  std::vector<double> ub(m.num_inputs());
  for (size_t k = 0; k < tr.t.size(); ++k) {
    const auto& x = tr.x[k];
    u(tr.t[k], ub.data());
    os << tr.t[k];
    for (size_t r = 0; r < rotors.size(); ++r) os << "," << ub[r];
    const auto [phi, theta, psi] = euler_zyx(x[6], x[7], x[8], x[9]);
    os << "," << x[0] << "," << x[1] << "," << x[2] << "," << x[6] << "," << x[7] << "," << x[8] << "," << x[9]
       << "," << phi << "," << theta << "," << psi << "," << x[3] << "," << x[4] << "," << x[5] << "," << x[10] << "," << x[11]
       << "," << x[12];
    for (int i = 13; i < m.num_states(); ++i) os << "," << x[i];
    os << "\n";
  }
  return os.str();
}

}  // namespace quadgen::runtime
