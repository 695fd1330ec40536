// parapm-attribute-error REFERENCE APPROX: how far a simplified mesh is from its original, in
// distance and in attributes (colour, texture coordinates, normals), measured by sampling the
// reference (engine/measure/attribute_error.h). For the benchmark report: "colour RMS error
// against the original". Exit status: 0 success, 2 an error (one line on stderr).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "io/mesh_io.h"
#include "measure/attribute_error.h"
#include "mesh/repair.h"
#include "util/error.h"

namespace {

using parapm::AttributeError;

struct Args {
  std::string reference;
  std::string approx;
  parapm::AttributeErrorOptions options;
  bool json = false;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Read and repaired as `parapm simplify` reads its input: repair validates what the reader let
// through (non-finite values, wedges of the wrong vertex) and drops degenerate and duplicate
// faces, so both meshes are measured as the engine sees them.
parapm::Mesh load(const std::string& path) {
  const auto start = std::chrono::steady_clock::now();
  parapm::Mesh mesh = parapm::repair_mesh(parapm::read_mesh(path)).mesh;
  spdlog::info("read {}: {} vertices, {} faces in {:.3f} s", path, mesh.vertex_count(),
               mesh.face_count(), seconds_since(start));
  return mesh;
}

// The struct's fields, plus the distances relative to the reference's bounding-box diagonal
// (what metro's figures in BENCHMARKS.md are relative to).
nlohmann::json to_json(const AttributeError& e) {
  const auto relative = [&](double value) { return e.diagonal > 0 ? value / e.diagonal : 0.0; };
  return {{"samples", e.samples},
          {"diagonal", e.diagonal},
          {"distance_rms", e.distance_rms},
          {"distance_max", e.distance_max},
          {"distance_rms_rel", relative(e.distance_rms)},
          {"distance_max_rel", relative(e.distance_max)},
          {"colors", e.colors},
          {"texcoords", e.texcoords},
          {"normals", e.normals},
          {"color_rms", e.color_rms},
          {"color_max", e.color_max},
          {"texcoord_rms", e.texcoord_rms},
          {"texcoord_max", e.texcoord_max},
          {"normal_rms_degrees", e.normal_rms_degrees},
          {"normal_max_degrees", e.normal_max_degrees},
          {"normal_samples_skipped", e.normal_samples_skipped}};
}

void print_text(const AttributeError& e) {
  std::printf("samples    %llu\n", (unsigned long long)e.samples);
  std::printf("diagonal   %.6g\n", e.diagonal);
  std::printf("distance   rms %.6g (%.3g of the diagonal), max %.6g (%.3g)\n", e.distance_rms,
              e.diagonal > 0 ? e.distance_rms / e.diagonal : 0.0, e.distance_max,
              e.diagonal > 0 ? e.distance_max / e.diagonal : 0.0);
  const auto channel = [](const char* name, bool present, double rms, double max,
                          const char* unit) {
    if (present)
      std::printf("%-10s rms %.6g%s, max %.6g%s\n", name, rms, unit, max, unit);
    else
      std::printf("%-10s not in both meshes\n", name);
  };
  channel("color", e.colors, e.color_rms, e.color_max, "");
  channel("texcoord", e.texcoords, e.texcoord_rms, e.texcoord_max, "");
  channel("normal", e.normals, e.normal_rms_degrees, e.normal_max_degrees, " degrees");
  if (e.normals && e.normal_samples_skipped)
    std::printf("normal     %llu samples without a direction skipped\n",
                (unsigned long long)e.normal_samples_skipped);
}

int run(const Args& args) {
  const parapm::Mesh reference = load(args.reference);
  const parapm::Mesh approx = load(args.approx);
  const auto start = std::chrono::steady_clock::now();
  const AttributeError error = parapm::measure_attribute_error(reference, approx, args.options);
  spdlog::info("measured {} samples of {} against {} ({} faces) in {:.3f} s", error.samples,
               args.reference, args.approx, approx.face_count(), seconds_since(start));
  if (args.json)
    std::cout << to_json(error).dump() << std::endl;
  else
    print_text(error);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_default_logger(spdlog::stderr_color_mt("parapm-attribute-error"));
  spdlog::set_pattern("%^[%L]%$ %v");

  CLI::App app{
      "parapm-attribute-error: distance, colour, texture-coordinate and normal error of APPROX "
      "against REFERENCE, at points drawn uniformly by area on REFERENCE and their closest "
      "points on APPROX.\nExit status: 0 success, 2 an error (one line on stderr)."};
  Args args;
  app.add_option("reference", args.reference, "The original mesh")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("approx", args.approx, "The simplified mesh")
      ->required()
      ->check(CLI::ExistingFile);
  // 0 is refused by the engine, with a shorter message than CLI11's range check prints.
  app.add_option("--samples", args.options.samples, "Points drawn on the reference (positive)")
      ->capture_default_str();
  app.add_option("--seed", args.options.seed, "Of the point draw: same seed, same figures")
      ->capture_default_str();
  app.add_flag("--json", args.json, "Print one JSON object on stdout");
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));

  try {
    app.parse(argc, argv);
    spdlog::set_level(spdlog::level::from_str(log_level));
    return run(args);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const parapm::Error& e) {
    std::fprintf(stderr, "parapm-attribute-error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "parapm-attribute-error: internal error: %s\n", e.what());
    return 2;
  }
}
