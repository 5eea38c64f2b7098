// What `robodamp identify cutting` reports (docs/identification.md): the tests' steady cuts read from the force
// records, and the coefficients fitted with their 95 % intervals, R^2 per axis and the feed's linearity, as text,
// JSON and a `material:` block. Off the real-time path.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "identify/cutting_coefficients.hpp"
#include "identify/cutting_records.hpp"

namespace robodamp::identify {

// The tests: a table (tests_path), or the record files (records: files, or a directory's files in name order)
// with one feed each and the spindle speed. Throws std::invalid_argument naming the options.
[[nodiscard]] std::vector<RecordTest> record_tests(const std::string& tests_path,
                                                   const std::vector<std::string>& records,
                                                   const std::vector<double>& feeds_mm, double rpm);

struct RecordMeans {
  std::vector<MeanForces> means;
  nlohmann::json json;  // each test's steady cut
};

// Each record's steady cut and its means; one line per record to `line` as it is read.
[[nodiscard]] RecordMeans means_from_records(const std::vector<RecordTest>& tests, const RecordSettings& s,
                                             const std::function<void(const std::string&)>& line);

struct CuttingReport {
  nlohmann::json json;
  std::string text;  // the coefficients, the fit's figures, the linearity's warnings
  std::string yaml;  // the material: block
};

// source: what the means came from ("force records" or the table's path); records: means_from_records' JSON
// (null for a table).
[[nodiscard]] CuttingReport cutting_report(const CuttingFit& f, const std::vector<MeanForces>& samples,
                                           const CuttingTest& t, const std::string& mode, const std::string& source,
                                           const nlohmann::json& records);

}  // namespace robodamp::identify
