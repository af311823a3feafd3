// `terravol bench`: the standing benchmarks (bench/suites.h), their JSON results and Markdown
// report with plots (bench/report.h). docs/benchmarks.md says what each figure means.
#pragma once

#include <CLI/CLI.hpp>

namespace terravol::bench {

void add_bench_command(CLI::App& app);  // terravol bench [--quick] [-o DIR] [--suites LIST] ...

}  // namespace terravol::bench
