#include "server/metrics/metrics_registry.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"

namespace motiondb::server {
namespace {

// Prometheus' float syntax: +Inf, -Inf, NaN, or the shortest text that reads back as `value`.
std::string Number(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  char text[32];
  const std::to_chars_result written = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, written.ptr);
}

// {a="x",b="y"} with `extra` (already formatted, such as le="0.1") last; empty for no labels.
std::string LabelSet(const std::vector<std::string>& names, const LabelValues& values,
                     const std::string& extra = "") {
  std::vector<std::string> pairs;
  for (size_t i = 0; i < names.size() && i < values.size(); ++i) {
    const std::string escaped =
        absl::StrReplaceAll(values[i], {{"\\", "\\\\"}, {"\"", "\\\""}, {"\n", "\\n"}});
    pairs.push_back(absl::StrCat(names[i], "=\"", escaped, "\""));
  }
  if (!extra.empty()) pairs.push_back(extra);
  return pairs.empty() ? "" : absl::StrCat("{", absl::StrJoin(pairs, ","), "}");
}

}  // namespace

void MetricsRegistry::Counter::Add(const LabelValues& labels, int64_t amount) {
  std::lock_guard<std::mutex> lock(mutex_);
  values_[labels] += amount;
}

void MetricsRegistry::Histogram::Observe(const LabelValues& labels, double value) {
  // The first bound at or above the value (le is "less than or equal"); past every bound, +Inf.
  const size_t bucket = std::lower_bound(bounds_.begin(), bounds_.end(), value) - bounds_.begin();
  std::lock_guard<std::mutex> lock(mutex_);
  Series& series = series_[labels];
  if (series.counts.empty()) series.counts.assign(bounds_.size() + 1, 0);
  ++series.counts[bucket];
  series.sum += value;
}

MetricsRegistry::Counter& MetricsRegistry::AddCounter(std::string name, std::string help,
                                                      std::vector<std::string> label_names) {
  Counter* counter = counters_.emplace_back(std::make_unique<Counter>()).get();
  families_.push_back({std::move(name), std::move(help), "counter", std::move(label_names), counter,
                       nullptr, nullptr});
  return *counter;
}

MetricsRegistry::Histogram& MetricsRegistry::AddHistogram(std::string name, std::string help,
                                                          std::vector<std::string> label_names,
                                                          std::vector<double> bounds) {
  // Histogram's constructor is private to the registry, so not make_unique.
  Histogram* histogram = histograms_.emplace_back(new Histogram(std::move(bounds))).get();
  families_.push_back({std::move(name), std::move(help), "histogram", std::move(label_names),
                       nullptr, histogram, nullptr});
  return *histogram;
}

void MetricsRegistry::AddGauge(std::string name, std::string help,
                               std::vector<std::string> label_names, GaugeReader read) {
  families_.push_back({std::move(name), std::move(help), "gauge", std::move(label_names), nullptr,
                       nullptr, std::move(read)});
}

std::string MetricsRegistry::Render() const {
  std::string out;
  for (const Family& family : families_) {
    const std::string help = absl::StrReplaceAll(family.help, {{"\\", "\\\\"}, {"\n", "\\n"}});
    absl::StrAppend(&out, "# HELP ", family.name, " ", help, "\n# TYPE ", family.name, " ",
                    family.type, "\n");
    const auto& names = family.label_names;
    if (family.counter != nullptr) {
      std::lock_guard<std::mutex> lock(family.counter->mutex_);
      for (const auto& [labels, value] : family.counter->values_) {
        absl::StrAppend(&out, family.name, LabelSet(names, labels), " ", value, "\n");
      }
    } else if (family.histogram != nullptr) {
      const Histogram& histogram = *family.histogram;
      std::lock_guard<std::mutex> lock(family.histogram->mutex_);
      for (const auto& [labels, series] : histogram.series_) {
        int64_t cumulative = 0;
        for (size_t b = 0; b < series.counts.size(); ++b) {
          cumulative += series.counts[b];
          const double bound = b < histogram.bounds_.size() ? histogram.bounds_[b] : INFINITY;
          absl::StrAppend(&out, family.name, "_bucket",
                          LabelSet(names, labels, absl::StrCat("le=\"", Number(bound), "\"")), " ",
                          cumulative, "\n");
        }
        absl::StrAppend(&out, family.name, "_sum", LabelSet(names, labels), " ", Number(series.sum),
                        "\n", family.name, "_count", LabelSet(names, labels), " ", cumulative,
                        "\n");
      }
    } else {
      for (const auto& [labels, value] : family.gauge()) {
        absl::StrAppend(&out, family.name, LabelSet(names, labels), " ", Number(value), "\n");
      }
    }
  }
  return out;
}

std::vector<double> ExponentialBounds(double first, double factor, int count) {
  std::vector<double> bounds;
  for (double bound = first; static_cast<int>(bounds.size()) < count; bound *= factor) {
    bounds.push_back(bound);
  }
  return bounds;
}

}  // namespace motiondb::server
