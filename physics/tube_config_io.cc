#include "physics/tube_config_io.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "core/common/errors.h"

namespace tubepick::physics {
namespace {

/// Non-blank lines of the text, each split into whitespace-separated tokens, with its 1-based
/// line number.
struct Line {
  int number;
  std::vector<std::string> tokens;
};

class LineReader {
 public:
  LineReader(const std::string& text, std::string source) : source_(std::move(source)) {
    std::istringstream in(text);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      std::istringstream fields(line);
      Line l{number, {}};
      for (std::string token; fields >> token;) l.tokens.push_back(token);
      if (!l.tokens.empty()) lines_.push_back(std::move(l));
    }
    last_line_ = number;
  }

  /// The next line, which must have `count` fields; `what` describes it for errors.
  const Line& Next(std::size_t count, const std::string& what) {
    if (next_ >= lines_.size()) Fail(last_line_ + 1, "unexpected end of file, expected " + what);
    const Line& line = lines_[next_++];
    if (line.tokens.size() != count) {
      Fail(line.number, "expected " + std::to_string(count) + " fields in " + what + ", got " +
                            std::to_string(line.tokens.size()));
    }
    return line;
  }

  bool AtEnd() const { return next_ >= lines_.size(); }
  int NextLineNumber() const { return AtEnd() ? last_line_ + 1 : lines_[next_].number; }

  [[noreturn]] void Fail(int line, const std::string& reason) const {
    throw InvalidArgument(source_ + ":" + std::to_string(line) + ": " + reason);
  }

  int Int(const Line& line, std::size_t field, const std::string& name) const {
    const std::string& token = line.tokens[field];
    int value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size()) {
      Fail(line.number, name + ": expected an integer, got '" + token + "'");
    }
    return value;
  }

  double Double(const Line& line, std::size_t field, const std::string& name) const {
    const std::string& token = line.tokens[field];
    double value = 0.0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(value)) {
      Fail(line.number, name + ": expected a finite number, got '" + token + "'");
    }
    return value;
  }

 private:
  std::string source_;
  std::vector<Line> lines_;
  std::size_t next_ = 0;
  int last_line_ = 0;
};

constexpr const char* kNodeLine = "a node line '<id> x y z radius'";
constexpr const char* kEdgeLine =
    "an edge line '<name> <node1> <node2> <order> <radius> cx cy cz qw qx qy qz <length>'";

TubeGeometry ParseTube(LineReader& in, int index) {
  const Line& header =
      in.Next(3, "tube header '<id> <n_nodes> <n_edges>' of tube " + std::to_string(index + 1));
  TubeGeometry tube;
  tube.id = in.Int(header, 0, "tube id");
  const int n_nodes = in.Int(header, 1, "number of nodes");
  const int n_edges = in.Int(header, 2, "number of edges");
  if (n_nodes < 1 || n_nodes > 100000)
    in.Fail(header.number, "number of nodes " + std::to_string(n_nodes) + " out of range 1..100000");
  if (n_edges < 0 || n_edges > 100000)
    in.Fail(header.number, "number of edges " + std::to_string(n_edges) + " out of range 0..100000");
  const std::string of_tube = " of tube " + std::to_string(tube.id);

  std::set<int> ids;
  for (int i = 0; i < n_nodes; ++i) {
    const Line& line = in.Next(5, std::string(kNodeLine) + " (node " + std::to_string(i + 1) + " of " +
                                      std::to_string(n_nodes) + of_tube + ")");
    TubeNode node;
    node.id = in.Int(line, 0, "node id");
    node.centre = Eigen::Vector3d(in.Double(line, 1, "x"), in.Double(line, 2, "y"), in.Double(line, 3, "z"));
    node.radius = in.Double(line, 4, "radius");
    if (!ids.insert(node.id).second)
      in.Fail(line.number, "duplicate node id " + std::to_string(node.id) + of_tube);
    if (node.radius < 0.0) in.Fail(line.number, "negative node radius " + line.tokens[4]);
    tube.nodes.push_back(node);
  }
  for (int i = 0; i < n_edges; ++i) {
    const Line& line = in.Next(13, std::string(kEdgeLine) + " (edge " + std::to_string(i + 1) + " of " +
                                       std::to_string(n_edges) + of_tube + ")");
    TubeEdge edge;
    edge.name = line.tokens[0];
    edge.node1 = in.Int(line, 1, "node1");
    edge.node2 = in.Int(line, 2, "node2");
    for (int node_id : {edge.node1, edge.node2}) {
      if (!ids.contains(node_id)) {
        in.Fail(line.number, "edge " + edge.name + " refers to node " + std::to_string(node_id) +
                                 ", which is not among the nodes" + of_tube);
      }
    }
    edge.order = in.Int(line, 3, "order");
    edge.radius = in.Double(line, 4, "radius");
    if (edge.radius <= 0.0) in.Fail(line.number, "edge radius must be > 0, got " + line.tokens[4]);
    edge.centre =
        Eigen::Vector3d(in.Double(line, 5, "cx"), in.Double(line, 6, "cy"), in.Double(line, 7, "cz"));
    const Eigen::Quaterniond q(in.Double(line, 8, "qw"), in.Double(line, 9, "qx"), in.Double(line, 10, "qy"),
                               in.Double(line, 11, "qz"));
    if (q.norm() < 1e-9) in.Fail(line.number, "edge " + edge.name + ": zero quaternion");
    edge.orientation = q.normalized();
    edge.length = in.Double(line, 12, "length");
    if (edge.length < 0.0) in.Fail(line.number, "negative edge length " + line.tokens[12]);
    tube.edges.push_back(edge);
  }
  return tube;
}

void AppendNumber(std::string& out, double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.9g", value);
  out += buffer;
}

}  // namespace

std::vector<TubeGeometry> ParseTubeConfigurations(const std::string& text, const std::string& source) {
  LineReader in(text, source);
  const Line& first = in.Next(1, "the number of tubes on the first line");
  const int count = in.Int(first, 0, "number of tubes");
  if (count < 0 || count > 100000)
    in.Fail(first.number, "number of tubes " + std::to_string(count) + " out of range 0..100000");
  std::vector<TubeGeometry> tubes;
  tubes.reserve(count);
  for (int i = 0; i < count; ++i) tubes.push_back(ParseTube(in, i));
  if (!in.AtEnd()) {
    in.Fail(in.NextLineNumber(),
            "unexpected content after the " + std::to_string(count) + " tubes the first line announces");
  }
  return tubes;
}

std::vector<TubeGeometry> ReadTubeConfigurations(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InvalidArgument("cannot open tube configurations file '" + path + "'");
  std::stringstream text;
  text << file.rdbuf();
  return ParseTubeConfigurations(text.str(), path);
}

std::string FormatTubeConfigurations(const std::vector<TubeGeometry>& tubes) {
  std::string out = std::to_string(tubes.size()) + "\n";
  for (const TubeGeometry& tube : tubes) {
    out += std::to_string(tube.id) + " " + std::to_string(tube.nodes.size()) + " " +
           std::to_string(tube.edges.size()) + "\n";
    for (const TubeNode& n : tube.nodes) {
      out += std::to_string(n.id);
      for (double v : {n.centre.x(), n.centre.y(), n.centre.z(), n.radius}) {
        out += ' ';
        AppendNumber(out, v);
      }
      out += '\n';
    }
    for (const TubeEdge& e : tube.edges) {
      if (e.name.empty() || e.name.find_first_of(" \t\r\n") != std::string::npos) {
        throw InvalidArgument("tube " + std::to_string(tube.id) + ": edge name '" + e.name +
                              "' must be one non-empty token");
      }
      out += e.name + " " + std::to_string(e.node1) + " " + std::to_string(e.node2) + " " +
             std::to_string(e.order);
      const Eigen::Quaterniond& q = e.orientation;
      for (double v :
           {e.radius, e.centre.x(), e.centre.y(), e.centre.z(), q.w(), q.x(), q.y(), q.z(), e.length}) {
        out += ' ';
        AppendNumber(out, v);
      }
      out += '\n';
    }
  }
  return out;
}

void WriteTubeConfigurations(const std::string& path, const std::vector<TubeGeometry>& tubes) {
  const std::string text = FormatTubeConfigurations(tubes);
  std::ofstream file(path, std::ios::binary);
  if (!file) throw InvalidArgument("cannot write tube configurations file '" + path + "'");
  file << text;
  if (!file.flush()) throw InvalidArgument("error while writing tube configurations file '" + path + "'");
}

}  // namespace tubepick::physics
