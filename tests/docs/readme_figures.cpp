// Checks that every figure README.md's "## Performance" section quotes is the
// figure docs/benchmarks.md records (tracker issue 26 item 7: one recorded run
// behind every published figure).
//
//   readme_figures README.md docs/benchmarks.md docs/readme_figures.spec
//
// The spec (format at its top) has one `figure` line per README figure, saying
// which table, column, rows and aggregate of docs/benchmarks.md give it and how
// it is written, and `allow` lines for the numbers in the section that are not
// measurements (cell counts, thread counts, targets). The checker
//   - computes and renders every figure and checks that the rendering is the
//     spec's text and that the text is in the Performance section;
//   - checks that every number in the section lies in a figure's or an allowed
//     text;
// and prints one line per mismatch. Exit status 0: all agree; 1: a mismatch;
// 2: a file could not be read or the spec is malformed.
//
// Standard library only: CI machines are only guaranteed a compiler, CMake and
// GoogleTest.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

bool read_file(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::stringstream ss;
  ss << in.rdbuf();
  out = ss.str();
  return true;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

// Runs of white space (newlines included) as one space: README lines wrap.
std::string squeeze(const std::string& s) {
  std::string out;
  bool space = false;
  for (char c : s) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      space = true;
      continue;
    }
    if (space && !out.empty()) out += ' ';
    space = false;
    out += c;
  }
  return out;
}

// ---------------------------------------------------------------- tables

struct Table {
  std::vector<std::string> headings;  // enclosing heading lines, outermost first
  int line = 0;                       // of the header row, 1-based
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  std::string innermost() const { return headings.empty() ? std::string() : headings.back(); }
  std::string path() const {
    std::string p;
    for (const auto& h : headings) p += (p.empty() ? "" : " > ") + h;
    return p;
  }
  int column(const std::string& name) const {
    if (name.size() > 1 && name[0] == '#') return std::atoi(name.c_str() + 1) - 1;
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
};

std::vector<std::string> cells_of(const std::string& line) {
  std::string s = trim(line);
  if (!s.empty() && s.front() == '|') s.erase(0, 1);
  if (!s.empty() && s.back() == '|') s.pop_back();
  std::vector<std::string> cells;
  std::string cell;
  for (char c : s) {
    if (c == '|') {
      cells.push_back(trim(cell));
      cell.clear();
    } else {
      cell += c;
    }
  }
  cells.push_back(trim(cell));
  return cells;
}

bool is_separator(const std::string& line) {
  std::string s = trim(line);
  if (s.size() < 3 || s[0] != '|') return false;
  return s.find_first_not_of("|-: ") == std::string::npos;
}

// Every markdown table (a header row, a |---| row, rows), with the headings
// above it. Headings inside ``` fences count too: the fenced runs of
// docs/benchmarks.md label their tables with them.
std::vector<Table> parse_tables(const std::string& text) {
  std::vector<Table> tables;
  std::vector<std::string> headings;  // index = level - 1
  const auto lines = split_lines(text);
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (!l.empty() && l[0] == '#') {
      size_t level = l.find_first_not_of('#');
      if (level != std::string::npos && l[level] == ' ') {
        headings.resize(level - 1);
        headings.push_back(trim(l));
        continue;
      }
    }
    if (trim(l).rfind('|', 0) == 0 && i + 1 < lines.size() && is_separator(lines[i + 1])) {
      Table t;
      for (const auto& h : headings)
        if (!h.empty()) t.headings.push_back(h);
      t.line = static_cast<int>(i) + 1;
      t.header = cells_of(l);
      size_t j = i + 2;
      for (; j < lines.size() && trim(lines[j]).rfind('|', 0) == 0; ++j) t.rows.push_back(cells_of(lines[j]));
      tables.push_back(std::move(t));
      i = j - 1;
    }
  }
  return tables;
}

// The first number in a cell ("20.9x", "99.60 (met)", "3.19 **no**", "22.3%").
std::optional<double> number_in(const std::string& cell) {
  for (size_t i = 0; i < cell.size(); ++i) {
    char c = cell[i];
    bool digit = std::isdigit(static_cast<unsigned char>(c));
    bool signed_digit = (c == '-' || c == '.') && i + 1 < cell.size() &&
                        std::isdigit(static_cast<unsigned char>(cell[i + 1]));
    if (digit || signed_digit) {
      std::string s;
      for (size_t j = i; j < cell.size(); ++j)
        if (cell[j] != ',') s += cell[j];  // 1,000
        else if (!(j + 1 < cell.size() && std::isdigit(static_cast<unsigned char>(cell[j + 1])))) break;
      char* end = nullptr;
      double v = std::strtod(s.c_str(), &end);
      if (end != s.c_str()) return v;
      return std::nullopt;
    }
  }
  return std::nullopt;
}

// ---------------------------------------------------------------- formatting

// printf-like: %% and %[,][.N](f|e|g|s); s = N significant digits written
// plainly; e drops the exponent's padding (5.8e-6); ',' groups thousands.
std::string format_number(double v, char conv, int prec, bool group) {
  char buf[128];
  // Half-way values in the table (4.45, 0.115) round up, as a reader rounds
  // the decimal they see, not its binary neighbour.
  double nudged = v + v * 1e-12;
  switch (conv) {
    case 'f':
      std::snprintf(buf, sizeof buf, "%.*f", prec < 0 ? 6 : prec, nudged);
      break;
    case 'g':
      std::snprintf(buf, sizeof buf, "%.*g", prec < 0 ? 6 : prec, v);
      break;
    case 'e': {
      std::snprintf(buf, sizeof buf, "%.*e", prec < 0 ? 6 : prec, nudged);
      std::string s = buf;
      size_t e = s.find('e');
      std::string mant = s.substr(0, e), exp = s.substr(e + 1);
      std::string sign = exp[0] == '-' ? "-" : "";
      std::string digits = exp.substr(1);
      digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size() - 1));
      return mant + "e" + sign + digits;
    }
    case 's': {
      int n = prec < 1 ? 1 : prec;
      if (v == 0) {
        std::snprintf(buf, sizeof buf, "0");
        break;
      }
      int mag = static_cast<int>(std::floor(std::log10(std::fabs(nudged))));
      int decimals = n - 1 - mag;
      if (decimals >= 0) {
        std::snprintf(buf, sizeof buf, "%.*f", decimals, nudged);
      } else {
        double unit = std::pow(10.0, -decimals);
        std::snprintf(buf, sizeof buf, "%.0f", std::round(nudged / unit) * unit);
      }
      break;
    }
    default:
      return "?";
  }
  std::string s = buf;
  if (group) {
    size_t start = (s[0] == '-') ? 1 : 0;
    size_t end = s.find('.');
    if (end == std::string::npos) end = s.size();
    std::string grouped = s.substr(0, start);
    for (size_t i = start; i < end; ++i) {
      if (i > start && (end - i) % 3 == 0) grouped += ',';
      grouped += s[i];
    }
    s = grouped + s.substr(end);
  }
  return s;
}

// Renders fmt with the values; "" and an error on a malformed format.
std::string render(const std::string& fmt, const std::vector<double>& values, std::string& error) {
  std::string out;
  size_t k = 0;
  for (size_t i = 0; i < fmt.size(); ++i) {
    if (fmt[i] != '%') {
      out += fmt[i];
      continue;
    }
    if (i + 1 < fmt.size() && fmt[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    size_t j = i + 1;
    bool group = false;
    int prec = -1;
    if (j < fmt.size() && fmt[j] == ',') {
      group = true;
      ++j;
    }
    if (j < fmt.size() && fmt[j] == '.') {
      ++j;
      prec = 0;
      while (j < fmt.size() && std::isdigit(static_cast<unsigned char>(fmt[j]))) prec = prec * 10 + (fmt[j++] - '0');
    }
    if (j >= fmt.size() || std::string("fegs").find(fmt[j]) == std::string::npos) {
      error = "bad conversion in format '" + fmt + "'";
      return "";
    }
    if (k >= values.size()) {
      error = "format '" + fmt + "' has more conversions than the aggregate gives values";
      return "";
    }
    out += format_number(values[k++], fmt[j], prec, group);
    i = j;
  }
  if (k != values.size()) {
    error = "format '" + fmt + "' has fewer conversions than the aggregate gives values";
    return "";
  }
  return out;
}

// Where the README has the figure's words with other numbers in it: the text
// fmt gives with any number in place of each conversion ("" if none).
std::string find_like(const std::string& section, const std::string& fmt) {
  // fmt as literal pieces between conversions.
  std::vector<std::string> pieces(1);
  for (size_t i = 0; i < fmt.size(); ++i) {
    if (fmt[i] == '%' && i + 1 < fmt.size() && fmt[i + 1] == '%') {
      pieces.back() += '%';
      ++i;
    } else if (fmt[i] == '%') {
      while (i < fmt.size() && std::string("fegs").find(fmt[i]) == std::string::npos) ++i;
      pieces.emplace_back();
    } else {
      pieces.back() += fmt[i];
    }
  }
  auto digit_at = [&](size_t q) { return q < section.size() && std::isdigit(static_cast<unsigned char>(section[q])); };
  auto number_end = [&](size_t p) {  // 12, 1,000, 0.5, 5.8e-6
    size_t q = p;
    if (!digit_at(q)) return q;
    while (digit_at(q) || ((section[q] == '.' || section[q] == ',') && digit_at(q + 1))) ++q;
    if (q < section.size() && section[q] == 'e' && (digit_at(q + 1) || (q + 1 < section.size() && section[q + 1] == '-' && digit_at(q + 2)))) {
      q += section[q + 1] == '-' ? 2 : 1;
      while (digit_at(q)) ++q;
    }
    return q;
  };
  const std::string& first = pieces[0];
  for (size_t start = 0; start < section.size(); ++start) {
    // A number starts the match when the format does: not inside another.
    if (first.empty() && start > 0 && std::isalnum(static_cast<unsigned char>(section[start - 1]))) continue;
    if (section.compare(start, first.size(), first) != 0) continue;
    size_t p = start + first.size();
    bool ok = true;
    for (size_t k = 1; k < pieces.size() && ok; ++k) {
      size_t q = number_end(p);
      if (q == p) ok = false;
      p = q;
      const std::string& lit = pieces[k];
      if (ok && section.compare(p, lit.size(), lit) != 0) ok = false;
      p += lit.size();
    }
    if (ok) return section.substr(start, p - start);
  }
  return "";
}

// ---------------------------------------------------------------- the spec

struct Line {
  int number = 0;
  std::string kind;  // figure | allow
  std::string text;
  std::vector<std::pair<std::string, std::string>> keys;
  std::vector<std::string> all(const std::string& key) const {
    std::vector<std::string> v;
    for (const auto& [k, val] : keys)
      if (k == key) v.push_back(val);
    return v;
  }
  std::optional<std::string> get(const std::string& key) const {
    for (const auto& [k, val] : keys)
      if (k == key) return val;
    return std::nullopt;
  }
};

// `kind "text" key=value key="value" flag`; "" quotes, \" and \\ escapes.
bool parse_spec_line(const std::string& raw, int number, Line& line, std::string& error) {
  line.number = number;
  size_t i = 0;
  auto skip = [&] {
    while (i < raw.size() && std::isspace(static_cast<unsigned char>(raw[i]))) ++i;
  };
  auto word = [&] {
    std::string w;
    while (i < raw.size() && !std::isspace(static_cast<unsigned char>(raw[i])) && raw[i] != '=') w += raw[i++];
    return w;
  };
  auto quoted = [&](std::string& out) {
    if (i >= raw.size() || raw[i] != '"') {
      // Unquoted value: up to white space.
      while (i < raw.size() && !std::isspace(static_cast<unsigned char>(raw[i]))) out += raw[i++];
      return true;
    }
    ++i;
    while (i < raw.size() && raw[i] != '"') {
      if (raw[i] == '\\' && i + 1 < raw.size()) ++i;
      out += raw[i++];
    }
    if (i >= raw.size()) return false;
    ++i;
    return true;
  };
  skip();
  line.kind = word();
  skip();
  if (line.kind != "figure" && line.kind != "allow") {
    error = "a line starts with `figure` or `allow`, not '" + line.kind + "'";
    return false;
  }
  if (i >= raw.size() || raw[i] != '"' || !quoted(line.text) || line.text.empty()) {
    error = "the README text comes second, in double quotes";
    return false;
  }
  for (skip(); i < raw.size(); skip()) {
    std::string key = word();
    std::string value;
    if (i < raw.size() && raw[i] == '=') {
      ++i;
      if (!quoted(value)) {
        error = "unterminated quote after " + key + "=";
        return false;
      }
    }
    line.keys.emplace_back(key, value);
  }
  return true;
}

// ---------------------------------------------------------------- figures

struct Condition {
  std::string column, op, value;
};

bool parse_condition(const std::string& s, Condition& c) {
  static const char* ops[] = {"!=", "!~", "<=", ">=", "=", "~", "<", ">"};
  size_t best = std::string::npos;
  std::string best_op;
  for (const char* op : ops) {
    size_t p = s.find(op);
    if (p != std::string::npos && (p < best || (p == best && std::string(op).size() > best_op.size()))) {
      best = p;
      best_op = op;
    }
  }
  if (best == std::string::npos) return false;
  c.column = trim(s.substr(0, best));
  c.op = best_op;
  c.value = trim(s.substr(best + best_op.size()));
  return true;
}

bool heading_matches(const Table& t, const std::string& pattern) {
  if (!pattern.empty() && pattern[0] == '#') {
    // The table's own heading, from its start: "## cornell box" is not
    // "### cornell box", nor a table under a ### below it.
    return t.innermost().rfind(pattern, 0) == 0;
  }
  return t.path().find(pattern) != std::string::npos;
}

struct Figure {
  std::string rendered;
  std::string where;  // for messages: table and column
};

// Computes one figure line; false and an error when the spec cannot be met.
bool compute(const Line& line, const std::vector<Table>& tables, const std::string& docs, Figure& fig,
             std::string& error) {
  const std::string fmt = line.get("fmt").value_or("%g");
  std::vector<double> values;
  if (auto quote = line.get("quote")) {
    // A figure the docs give in prose: the quote must be in docs/benchmarks.md.
    if (squeeze(docs).find(squeeze(*quote)) == std::string::npos) {
      error = "docs/benchmarks.md does not say '" + *quote + "'";
      return false;
    }
    int pick = std::atoi(line.get("pick").value_or("1").c_str());
    int n = 0;
    const std::string& q = *quote;
    for (size_t i = 0; i < q.size(); ++i) {
      if (std::isdigit(static_cast<unsigned char>(q[i])) && (i == 0 || !std::isalnum(static_cast<unsigned char>(q[i - 1])))) {
        if (++n == pick) {
          values.push_back(*number_in(q.substr(i)));
          break;
        }
        while (i < q.size() && (std::isdigit(static_cast<unsigned char>(q[i])) || q[i] == '.')) ++i;
      }
    }
    if (values.empty()) {
      error = "no number " + std::to_string(pick) + " in the quote";
      return false;
    }
    fig.where = "quote '" + *quote + "'";
    fig.rendered = render(fmt, values, error);
    return error.empty();
  }

  const auto patterns = line.all("table");
  const auto cols = line.all("col");  // several: agg=one gives one value per column
  const auto col = line.get("col");
  const std::string agg = line.get("agg").value_or("one");
  if (cols.size() > 1 && agg != "one") {
    error = "several col= need agg=one";
    return false;
  }
  if (patterns.empty() || (!col && agg != "count")) {
    error = "a figure names table= and col= (or quote=)";
    return false;
  }
  std::vector<Condition> conditions;
  for (const auto& w : line.all("where")) {
    Condition c;
    if (!parse_condition(w, c)) {
      error = "where='" + w + "' has no operator (= != ~ !~ < <= > >=)";
      return false;
    }
    conditions.push_back(c);
  }
  const auto over = line.get("over");
  const std::string nth = line.get("nth").value_or("1");

  std::vector<const Table*> matched;
  for (const auto& t : tables) {
    bool any = false;
    for (const auto& p : patterns) any = any || heading_matches(t, p);
    if (!any) continue;
    if (nth == "all") {
      // Every matching table that has the columns.
      bool has = !over || t.column(*over) >= 0;
      for (const auto& name : cols) has = has && t.column(name) >= 0;
      for (const auto& c : conditions) has = has && t.column(c.column) >= 0;
      if (!has) continue;
    }
    matched.push_back(&t);
  }
  if (nth != "all") {
    size_t k = static_cast<size_t>(std::atoi(nth.c_str()));
    if (k < 1 || k > matched.size()) {
      error = "no table " + nth + " under a heading '" + patterns[0] + "' (" + std::to_string(matched.size()) +
              " found)";
      return false;
    }
    matched = {matched[k - 1]};
  }
  if (matched.empty()) {
    error = "no table under a heading '" + patterns[0] + "' has the columns named";
    return false;
  }
  fig.where = "table '" + matched[0]->innermost() + "'" +
              (matched.size() > 1 ? " and " + std::to_string(matched.size() - 1) + " more" : "") +
              (col ? ", column '" + *col + "'" + (cols.size() > 1 ? " ..." : "") : "") + (over ? " / '" + *over + "'" : "");

  const double scale = std::atof(line.get("scale").value_or("1").c_str());
  const bool inv = line.get("inv").has_value();
  size_t rows = 0;
  for (const Table* t : matched) {
    int oi = over ? t->column(*over) : -1;
    for (const auto& name : cols) {
      if (t->column(name) < 0) {
        error = "table '" + t->innermost() + "' (line " + std::to_string(t->line) + ") has no column '" + name + "'";
        return false;
      }
    }
    if (over && oi < 0) {
      error = "table '" + t->innermost() + "' (line " + std::to_string(t->line) + ") has no column '" + *over + "'";
      return false;
    }
    for (const auto& row : t->rows) {
      bool keep = true;
      for (const auto& c : conditions) {
        int k = t->column(c.column);
        if (k < 0) {
          error = "table '" + t->innermost() + "' has no column '" + c.column + "'";
          return false;
        }
        std::string cell = k < static_cast<int>(row.size()) ? row[k] : "";
        if (c.op == "=") keep = keep && cell == c.value;
        else if (c.op == "!=") keep = keep && cell != c.value;
        else if (c.op == "~") keep = keep && cell.find(c.value) != std::string::npos;
        else if (c.op == "!~") keep = keep && cell.find(c.value) == std::string::npos;
        else {
          auto a = number_in(cell);
          double b = std::atof(c.value.c_str());
          if (!a) keep = false;
          else if (c.op == "<") keep = keep && *a < b;
          else if (c.op == "<=") keep = keep && *a <= b;
          else if (c.op == ">") keep = keep && *a > b;
          else if (c.op == ">=") keep = keep && *a >= b;
        }
      }
      if (!keep) continue;
      ++rows;
      if (agg == "count") continue;
      auto cellv = [&](int k) -> std::optional<double> {
        return k < static_cast<int>(row.size()) ? number_in(row[k]) : std::nullopt;
      };
      for (const auto& name : cols) {
        auto v = cellv(t->column(name));
        if (!v) {
          error = "no number in column '" + name + "' of a selected row of table '" + t->innermost() + "'";
          return false;
        }
        double x = *v;
        if (over) {
          auto d = cellv(oi);
          if (!d || *d == 0) {
            error = "no number (or zero) in column '" + *over + "' of a selected row";
            return false;
          }
          x /= *d;
        }
        if (inv) x = 1.0 / x;
        values.push_back(x * scale);
      }
    }
  }
  if (rows == 0) {
    error = "no row of " + fig.where + " passes the where= filters";
    return false;
  }
  std::vector<double> out;
  if (agg != "one") std::sort(values.begin(), values.end());
  if (agg == "count") out = {static_cast<double>(rows)};
  else if (agg == "one") {
    if (rows != 1) {
      error = "agg=one but " + std::to_string(rows) + " rows pass the filters";
      return false;
    }
    out = values;
  } else if (agg == "min") out = {values.front()};
  else if (agg == "max") out = {values.back()};
  else if (agg == "range") out = {values.front(), values.back()};
  else if (agg == "median") {
    size_t n = values.size();
    out = {n % 2 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2};
  } else if (agg == "mean") {
    double s = 0;
    for (double v : values) s += v;
    out = {s / static_cast<double>(values.size())};
  } else if (agg == "sum") {
    double s = 0;
    for (double v : values) s += v;
    out = {s};
  } else {
    error = "unknown agg '" + agg + "' (one min max range median mean sum count)";
    return false;
  }
  fig.rendered = render(fmt, out, error);
  return error.empty();
}

// The "## Performance" section: from its heading to the next "## " heading or
// the end of the file.
std::string performance_section(const std::string& readme) {
  const auto lines = split_lines(readme);
  std::string out;
  bool in = false;
  for (const auto& l : lines) {
    if (l.rfind("## ", 0) == 0) {
      if (in) break;
      in = trim(l) == "## Performance";
    }
    if (in) out += l + "\n";
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: readme_figures README.md docs/benchmarks.md docs/readme_figures.spec\n";
    return 2;
  }
  std::string readme, docs, spec;
  for (auto [path, out] : {std::pair{argv[1], &readme}, {argv[2], &docs}, {argv[3], &spec}}) {
    if (!read_file(path, *out)) {
      std::cerr << "cannot read " << path << "\n";
      return 2;
    }
  }
  const std::string section = squeeze(performance_section(readme));
  if (section.empty()) {
    std::cerr << argv[1] << " has no '## Performance' section\n";
    return 2;
  }
  const auto tables = parse_tables(docs);

  std::vector<Line> lines;
  int number = 0;
  bool malformed = false;
  for (const auto& raw : split_lines(spec)) {
    ++number;
    std::string t = trim(raw);
    if (t.empty() || t[0] == '#') continue;
    Line line;
    std::string error;
    if (!parse_spec_line(t, number, line, error)) {
      std::cerr << argv[3] << ":" << number << ": " << error << "\n";
      malformed = true;
      continue;
    }
    if (line.kind == "allow" && !line.get("reason")) {
      std::cerr << argv[3] << ":" << number << ": an allow line gives its reason=\n";
      malformed = true;
      continue;
    }
    lines.push_back(line);
  }
  if (malformed) return 2;

  int mismatches = 0, figures = 0, allowed = 0;
  std::vector<bool> covered(section.size(), false);
  auto cover = [&](const std::string& text) {
    const std::string s = squeeze(text);
    bool found = false;
    for (size_t p = section.find(s); p != std::string::npos; p = section.find(s, p + 1)) {
      found = true;
      std::fill(covered.begin() + p, covered.begin() + p + s.size(), true);
    }
    return found;
  };
  for (const auto& line : lines) {
    if (line.kind == "allow") {
      ++allowed;
      if (!cover(line.text)) {
        std::cout << "docs/readme_figures.spec:" << line.number << ": allowed text '" << line.text
                  << "' is not in README's Performance section (remove the line)\n";
        ++mismatches;
      }
      continue;
    }
    ++figures;
    Figure fig;
    std::string error;
    if (!compute(line, tables, docs, fig, error)) {
      std::cout << "docs/readme_figures.spec:" << line.number << ": '" << line.text << "': " << error << "\n";
      ++mismatches;
      continue;
    }
    const bool in_readme = cover(line.text);
    if (fig.rendered != line.text) {
      std::cout << "README says '" << line.text << "', docs/benchmarks.md gives '" << fig.rendered << "' ("
                << fig.where << "; docs/readme_figures.spec:" << line.number << ")\n";
      ++mismatches;
    }
    if (!in_readme) {
      const std::string like = find_like(section, line.get("fmt").value_or("%g"));
      if (!like.empty())
        std::cout << "README says '" << like << "', docs/benchmarks.md gives '" << fig.rendered << "' (" << fig.where
                  << "; docs/readme_figures.spec:" << line.number << ")\n";
      else
        std::cout << "README's Performance section does not say '" << line.text << "'; docs/benchmarks.md gives '"
                  << fig.rendered << "' (" << fig.where << "; docs/readme_figures.spec:" << line.number << ")\n";
      ++mismatches;
    }
  }

  // Every number in the section belongs to a figure or an allowed text.
  for (size_t i = 0; i < section.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(section[i]))) continue;
    if (i > 0) {
      unsigned char prev = static_cast<unsigned char>(section[i - 1]);
      if (std::isalnum(prev) || prev == '_' || prev == '.') {
        while (i < section.size() && std::isalnum(static_cast<unsigned char>(section[i]))) ++i;
        continue;  // part of a name: rtcIntersect1, p95, LDC_2
      }
    }
    size_t j = i;
    while (j < section.size() &&
           (std::isdigit(static_cast<unsigned char>(section[j])) ||
            ((section[j] == '.' || section[j] == ',') && j + 1 < section.size() &&
             std::isdigit(static_cast<unsigned char>(section[j + 1])))))
      ++j;
    if (j + 1 < section.size() && section[j] == 'e' &&
        (std::isdigit(static_cast<unsigned char>(section[j + 1])) || section[j + 1] == '-')) {
      ++j;
      if (section[j] == '-') ++j;
      while (j < section.size() && std::isdigit(static_cast<unsigned char>(section[j]))) ++j;
    }
    if (!std::all_of(covered.begin() + i, covered.begin() + j, [](bool b) { return b; })) {
      size_t from = i >= 30 ? i - 30 : 0;
      std::cout << "README's Performance section has the number '" << section.substr(i, j - i) << "' in '..."
                << section.substr(from, j + 30 - from) << "...', which no figure or allow line of "
                << "docs/readme_figures.spec covers\n";
      ++mismatches;
    }
    i = j;
  }

  if (mismatches) {
    std::cout << mismatches << " mismatch(es) between README.md's Performance section and docs/benchmarks.md\n";
    return 1;
  }
  std::cout << "README.md's Performance section: " << figures << " figures agree with docs/benchmarks.md ("
            << allowed << " allowed texts that are not measurements)\n";
  return 0;
}
