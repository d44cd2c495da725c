// A small Prometheus registry: counters and histograms with labels, observed where the server
// already times its work, and gauges read when scraped; rendered in the text exposition format
// 0.0.4 (https://prometheus.io/docs/instrumenting/exposition_formats/).
//
// Families are added while the server starts, before any thread observes them, and live as long
// as the registry. Thread-safe: observing and rendering may run on any threads at once (each
// family has its own mutex; gauges are read outside every lock).
#ifndef MOTIONDB_SERVER_METRICS_METRICS_REGISTRY_H_
#define MOTIONDB_SERVER_METRICS_METRICS_REGISTRY_H_

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace motiondb::server {

using LabelValues = std::vector<std::string>;

class MetricsRegistry {
 public:
  // A family of counters, one per set of label values (in the order of the family's names).
  class Counter {
   public:
    void Add(const LabelValues& labels, int64_t amount = 1);

   private:
    friend class MetricsRegistry;
    std::mutex mutex_;
    std::map<LabelValues, int64_t> values_;
  };

  // A family of histograms over fixed upper bounds (ascending; +Inf is implied).
  class Histogram {
   public:
    void Observe(const LabelValues& labels, double value);

   private:
    friend class MetricsRegistry;
    struct Series {
      std::vector<int64_t> counts;  // per bound, not cumulative; the last is +Inf's
      double sum = 0;
    };
    explicit Histogram(std::vector<double> bounds) : bounds_(std::move(bounds)) {}
    std::vector<double> bounds_;
    std::mutex mutex_;
    std::map<LabelValues, Series> series_;
  };

  // Every sample of a gauge family now: label values and value.
  using GaugeReader = std::function<std::vector<std::pair<LabelValues, double>>()>;

  // `name` and `label_names` follow Prometheus' rules (snake_case, counters ending in _total,
  // units in the name); `help` is one line. The registry keeps the family.
  Counter& AddCounter(std::string name, std::string help, std::vector<std::string> label_names);
  Histogram& AddHistogram(std::string name, std::string help, std::vector<std::string> label_names,
                          std::vector<double> bounds);
  void AddGauge(std::string name, std::string help, std::vector<std::string> label_names,
                GaugeReader read);

  // Every family in the order added, as the text format.
  std::string Render() const;

 private:
  struct Family {
    std::string name, help, type;
    std::vector<std::string> label_names;
    Counter* counter = nullptr;
    Histogram* histogram = nullptr;
    GaugeReader gauge;
  };

  std::vector<Family> families_;
  std::vector<std::unique_ptr<Counter>> counters_;
  std::vector<std::unique_ptr<Histogram>> histograms_;
};

// Upper bounds from `first` multiplying by `factor`, `count` of them (1, 2, 4, ... for 1, 2).
std::vector<double> ExponentialBounds(double first, double factor, int count);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_METRICS_METRICS_REGISTRY_H_
