#include "step_references.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hg::geometry {
namespace {

constexpr std::uint64_t kNoName = std::numeric_limits<std::uint64_t>::max();

// One entity instance: "#20 = ORIENTED_EDGE('',*,*,#21,.F.);" has the name 20, the type
// ORIENTED_EDGE and the reference 21; a complex instance "#7 = (A() B(#3));" has the type "(".
struct Entity {
  std::uint64_t name;
  std::string_view type;
  std::size_t firstReference;
  std::size_t references;
};

struct ReferenceGraph {
  std::vector<Entity> entities;
  std::vector<std::uint64_t> references;  // the names each entity refers to, entity by entity
};

bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
bool isKeyword(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || isDigit(c) || c == '_'; }

// Reads Part 21's lexical structure only as far as the references need: strings ('it''s')
// and binaries ("0F") are skipped whole, comments too, and every "#<digits>" is a name where
// an instance begins ("#20 =") and a reference inside one.
class Part21Scanner {
 public:
  explicit Part21Scanner(std::string_view text) : text_(text) {}

  ReferenceGraph scan() {
    ReferenceGraph graph;
    bool inEntity = false;
    while (at_ < text_.size()) {
      const char c = text_[at_];
      if (c == '\'') {
        skipString();
      } else if (c == '"') {
        skipPast('"', 1);
      } else if (c == '/' && next() == '*') {
        skipPast('/', 2, '*');
      } else if (c == '#') {
        ++at_;
        const std::uint64_t name = number();
        if (inEntity) {
          graph.references.push_back(name);
        } else if (skipSpace(); at_ < text_.size() && text_[at_] == '=') {
          ++at_;
          skipSpace();
          graph.entities.push_back({name, type(), graph.references.size(), 0});
          inEntity = true;
        }
      } else if (c == ';') {
        ++at_;
        if (inEntity) graph.entities.back().references = graph.references.size() - graph.entities.back().firstReference;
        inEntity = false;
      } else {
        ++at_;
      }
    }
    if (inEntity) graph.entities.back().references = graph.references.size() - graph.entities.back().firstReference;
    return graph;
  }

 private:
  char next() const { return at_ + 1 < text_.size() ? text_[at_ + 1] : '\0'; }

  void skipSpace() {
    while (at_ < text_.size() && isSpace(text_[at_])) ++at_;
  }

  // 'text', where '' is a quote inside it.
  void skipString() {
    for (++at_; at_ < text_.size(); ++at_) {
      if (text_[at_] != '\'') continue;
      if (next() != '\'') break;
      ++at_;
    }
    ++at_;
  }

  // Past the closing `last` (preceded by `before`, if given) of a token `open` characters long.
  void skipPast(char last, std::size_t open, char before = '\0') {
    for (at_ += open; at_ < text_.size(); ++at_)
      if (text_[at_] == last && (before == '\0' || text_[at_ - 1] == before)) break;
    ++at_;
  }

  // Saturates: a name too long for 64 bits is one name, which is enough to follow it.
  std::uint64_t number() {
    std::uint64_t value = 0;
    bool any = false;
    for (; at_ < text_.size() && isDigit(text_[at_]); ++at_) {
      any = true;
      const auto digit = static_cast<std::uint64_t>(text_[at_] - '0');
      value = value > (kNoName - 1 - digit) / 10 ? kNoName - 1 : value * 10 + digit;
    }
    return any ? value : kNoName;
  }

  std::string_view type() {
    const std::size_t start = at_;
    if (at_ < text_.size() && text_[at_] == '(') return text_.substr(at_, 1);  // complex: scanned on
    while (at_ < text_.size() && isKeyword(text_[at_])) ++at_;
    return text_.substr(start, at_ - start);
  }

  std::string_view text_;
  std::size_t at_ = 0;
};

// What a walk of the graph found: the longest chain of references and where it starts, or
// a cycle, as the entities on it.
struct Walk {
  std::size_t depth = 0;
  std::size_t deepest = 0;     // the entity that starts the longest chain
  std::vector<std::size_t> cycle;  // entities, each referring to the next and the last to the first
};

// Depth-first over every entity, without recursion (the point is not to need the stack
// OCCT would have needed): depth[e] = 1 + the largest depth among what e refers to.
Walk walk(const ReferenceGraph& graph, std::size_t stopAbove) {
  const std::size_t n = graph.entities.size();
  std::unordered_map<std::uint64_t, std::size_t> index;
  index.reserve(n);
  for (std::size_t e = 0; e < n; ++e) index.emplace(graph.entities[e].name, e);  // the first of a name
  enum : std::uint8_t { kUnseen, kOnPath, kDone };
  std::vector<std::uint8_t> state(n, kUnseen);
  std::vector<std::size_t> depth(n, 1);
  std::vector<std::pair<std::size_t, std::size_t>> path;  // entity, its next reference to follow
  Walk out;
  for (std::size_t root = 0; root < n; ++root) {
    if (state[root] != kUnseen) continue;
    path.push_back({root, 0});
    state[root] = kOnPath;
    while (!path.empty()) {
      const std::size_t e = path.back().first;  // a copy: pushing and popping move the path
      std::size_t& next = path.back().second;
      const Entity& entity = graph.entities[e];
      if (next == entity.references) {
        state[e] = kDone;
        if (depth[e] > out.depth) out = {depth[e], e, {}};
        path.pop_back();
        if (!path.empty()) {
          std::size_t& parent = depth[path.back().first];
          parent = std::max(parent, depth[e] + 1);
        }
        continue;
      }
      const auto found = index.find(graph.references[entity.firstReference + next++]);
      if (found == index.end()) continue;  // a dangling reference is OCCT's to report
      const std::size_t child = found->second;
      if (state[child] == kDone) {
        depth[e] = std::max(depth[e], depth[child] + 1);
      } else if (state[child] == kOnPath) {
        auto from = std::find_if(path.begin(), path.end(), [child](const auto& p) { return p.first == child; });
        for (; from != path.end(); ++from) out.cycle.push_back(from->first);
        return out;
      } else {
        state[child] = kOnPath;
        path.push_back({child, 0});
        if (path.size() > stopAbove) return {path.size(), root, {}};
      }
    }
  }
  return out;
}

std::string named(const Entity& entity) {
  std::string words = "#" + std::to_string(entity.name);
  if (!entity.type.empty() && entity.type != "(") words += " (" + std::string(entity.type.substr(0, 64)) + ")";
  return words;
}

std::string describeCycle(const ReferenceGraph& graph, const std::vector<std::size_t>& cycle) {
  const Entity& first = graph.entities[cycle.front()];
  if (cycle.size() == 1) return "entity " + named(first) + " refers to itself";
  constexpr std::size_t kShown = 6;
  std::string words = "entities refer to each other in a circle: " + named(first);
  for (std::size_t i = 1; i < std::min(cycle.size(), kShown); ++i) words += " -> " + named(graph.entities[cycle[i]]);
  if (cycle.size() > kShown) words += " -> ... (" + std::to_string(cycle.size()) + " entities)";
  return words + " -> #" + std::to_string(first.name);
}

}  // namespace

std::string stepReferenceProblem(std::string_view text, std::size_t maxDepth) {
  const ReferenceGraph graph = Part21Scanner(text).scan();
  const Walk found = walk(graph, maxDepth);
  if (!found.cycle.empty()) return describeCycle(graph, found.cycle);
  if (found.depth > maxDepth)
    return "references nest deeper than " + std::to_string(maxDepth) + " entities, from " +
           named(graph.entities[found.deepest]);
  return "";
}

std::size_t stepReferenceDepth(std::string_view text) {
  const Walk found = walk(Part21Scanner(text).scan(), std::numeric_limits<std::size_t>::max());
  return found.cycle.empty() ? found.depth : std::numeric_limits<std::size_t>::max();
}

}  // namespace hg::geometry
