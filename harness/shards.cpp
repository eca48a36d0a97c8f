// shards — the slices of a many-unit command and their merge (shards.hpp).
#include "harness/shards.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <stdexcept>

namespace autumn {

Shard parse_shard(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("--shard '" + text + "': " + why + " (expected K/N, 1 <= K <= N, as in 2/8)");
  };
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw bad("no '/'");
  const auto number = [&](const std::string& part) {
    if (part.empty() || part.size() > 6 ||
        !std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; }))
      throw bad("'" + part + "' is not a whole number");
    return std::stoi(part);
  };
  Shard s;
  s.index = number(text.substr(0, slash));
  s.count = number(text.substr(slash + 1));
  if (s.count < 1 || s.count > 100000) throw bad("N must be from 1 to 100000");
  if (s.index < 1 || s.index > s.count) throw bad("K must be from 1 to N");
  return s;
}

size_t shard_unit_index(const Shard& s, size_t i) {
  return static_cast<size_t>(s.index - 1) + i * static_cast<size_t>(s.count);
}

nlohmann::json shard_json(const Shard& s, const std::string& unit_key, size_t units,
                          const std::vector<size_t>& skipped) {
  nlohmann::json j = {{"index", s.index}, {"count", s.count}, {unit_key, units}};
  if (!skipped.empty()) j["skipped"] = skipped;
  return j;
}

std::vector<nlohmann::json> read_json_files(const std::vector<std::string>& files) {
  std::vector<nlohmann::json> out;
  for (const std::string& f : files) {
    std::ifstream in(f);
    if (!in) throw std::runtime_error(f + ": cannot read it");
    try {
      out.push_back(nlohmann::json::parse(in));
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(f + ": not JSON (" + e.what() + ")");
    }
  }
  return out;
}

namespace {

struct ShardInfo {
  Shard shard;
  size_t units = 0;
  std::vector<size_t> skipped;
};

// The units of shard `index` of `count` over `units`.
size_t share(size_t units, int index, int count) {
  const size_t first = static_cast<size_t>(index - 1);
  return units > first ? (units - first - 1) / static_cast<size_t>(count) + 1 : 0;
}

ShardInfo shard_info(const nlohmann::json& report, const std::string& name, const ShardFormat& f) {
  std::vector<std::string> keys = f.settings;
  keys.insert(keys.begin(), f.rows);
  for (const std::string& key : keys)
    if (!report.is_object() || !report.contains(key))
      throw std::runtime_error(name + ": not the JSON of `autumn " + f.command + "` (no \"" + key + "\")");
  if (!report.at(f.rows).is_array())
    throw std::runtime_error(name + ": not the JSON of `autumn " + f.command + "` (\"" + f.rows + "\" is not a list)");
  if (!report.contains("shard"))
    throw std::runtime_error(name + ": not a shard (it has no \"shard\"; run `autumn " + f.command +
                             " ... --shard K/N --json-out FILE`)");
  ShardInfo s;
  try {
    const auto& j = report.at("shard");
    s.shard = {j.at("index").get<int>(), j.at("count").get<int>()};
    s.units = j.at(f.units).get<size_t>();
    if (j.contains("skipped")) s.skipped = j.at("skipped").get<std::vector<size_t>>();
  } catch (const nlohmann::json::exception&) {
    throw std::runtime_error(name + ": its \"shard\" is not {\"index\", \"count\", \"" + f.units +
                             "\"} of whole numbers");
  }
  if (s.shard.count < 1 || s.shard.index < 1 || s.shard.index > s.shard.count)
    throw std::runtime_error(name + ": its \"shard\" " + report.at("shard").dump() + " is not K of N, 1 <= K <= N");
  std::vector<size_t> sorted = s.skipped;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw std::runtime_error(name + ": its \"skipped\" names a unit twice");
  for (size_t u : s.skipped)
    if (u >= s.units || u % static_cast<size_t>(s.shard.count) != static_cast<size_t>(s.shard.index - 1))
      throw std::runtime_error(name + ": its \"skipped\" " + std::to_string(u) + " is not one of its " + f.units);
  return s;
}

std::string brief(const nlohmann::json* j) {
  if (!j) return "absent";
  std::string s = j->dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// Where `a` (this file's) and `b` (the first file's) first differ: "key/sub is X here, Y there" ("" when equal).
std::string first_difference(const nlohmann::json& a, const nlohmann::json& b, const std::string& path) {
  if (a == b) return "";
  if (a.is_object() && b.is_object()) {
    std::map<std::string, bool> keys;
    for (const auto& [k, v] : a.items()) keys[k] = true;
    for (const auto& [k, v] : b.items()) keys[k] = true;
    for (const auto& [k, unused] : keys) {
      const nlohmann::json* x = a.contains(k) ? &a.at(k) : nullptr;
      const nlohmann::json* y = b.contains(k) ? &b.at(k) : nullptr;
      if (x && y) {
        if (std::string d = first_difference(*x, *y, path + "/" + k); !d.empty()) return d;
      } else {
        return path + "/" + k + " is " + brief(x) + " here, " + brief(y) + " there";
      }
    }
  }
  return path + " is " + brief(&a) + " here, " + brief(&b) + " there";
}

// Every file against the first: the same run (count, units, settings), each index once, its share of rows.
std::vector<ShardInfo> check_shards(const std::vector<nlohmann::json>& reports, const std::vector<std::string>& names,
                                    const ShardFormat& f) {
  std::vector<ShardInfo> infos;
  std::map<int, std::string> seen;  // index -> file
  for (size_t i = 0; i < reports.size(); ++i) {
    const ShardInfo s = shard_info(reports[i], names[i], f);
    const ShardInfo& first = infos.empty() ? s : infos[0];
    const auto which = [&](const ShardInfo& x) {
      return std::to_string(x.shard.index) + "/" + std::to_string(x.shard.count) + " of " + std::to_string(x.units) +
             " " + f.units;
    };
    if (s.shard.count != first.shard.count || s.units != first.units)
      throw std::runtime_error(names[i] + ": shard " + which(s) + " is not of the same run as " + names[0] + " (" +
                               which(first) + ")");
    for (const std::string& key : f.settings)
      if (std::string d = first_difference(reports[i].at(key), reports[0].at(key), key); !d.empty())
        throw std::runtime_error(names[i] + ": not of the same run as " + names[0] + ": " + d);
    if (auto [at, fresh] = seen.emplace(s.shard.index, names[i]); !fresh)
      throw std::runtime_error(names[i] + ": shard " + std::to_string(s.shard.index) + " is also " + at->second);
    const size_t mine = share(s.units, s.shard.index, s.shard.count) - s.skipped.size();
    if (reports[i].at(f.rows).size() != mine)
      throw std::runtime_error(names[i] + ": shard " + which(s) + " has " +
                               std::to_string(reports[i].at(f.rows).size()) + " rows, not " + std::to_string(mine));
    infos.push_back(s);
  }
  if (static_cast<int>(seen.size()) != infos[0].shard.count) {
    std::string missing;
    for (int k = 1; k <= infos[0].shard.count && missing.size() < 200; ++k)
      if (!seen.count(k)) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
    throw std::runtime_error("shards missing: " + missing + " (of " + std::to_string(infos[0].shard.count) + ")");
  }
  return infos;
}

}  // namespace

MergedShards merge_shards(const std::vector<nlohmann::json>& reports, const std::vector<std::string>& names,
                          const ShardFormat& f) {
  if (reports.empty()) throw std::runtime_error("no shard files to merge");
  const std::vector<ShardInfo> infos = check_shards(reports, names, f);
  const size_t count = static_cast<size_t>(infos[0].shard.count), units = infos[0].units;
  std::vector<const nlohmann::json*> rows_of(count);  // by index - 1
  std::vector<bool> skipped(units);
  for (size_t i = 0; i < reports.size(); ++i) {
    rows_of[static_cast<size_t>(infos[i].shard.index - 1)] = &reports[i].at(f.rows);
    for (size_t u : infos[i].skipped) skipped[u] = true;
  }
  MergedShards m{nlohmann::json::object(), nlohmann::json::array()};
  for (const std::string& key : f.settings) m.settings[key] = reports[0].at(key);
  std::vector<size_t> next(count);
  for (size_t u = 0; u < units; ++u)
    if (!skipped[u]) m.rows.push_back(rows_of[u % count]->at(next[u % count]++));
  return m;
}

}  // namespace autumn
