#include "bench/report.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "app/output/write_file.h"
#include "bench/plot.h"

namespace terravol::bench {

namespace {

using nlohmann::json;

std::string num(double v, const char* format = "%.3g") {
  if (std::isinf(v)) return "inf";
  if (std::isnan(v)) return "n/a";
  char b[48];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

// "median (p10-p90)" of a Summary.
std::string spread(const json& s, const char* format = "%.3g") {
  return num(s["median"].get<double>(), format) + " (" + num(s["p10"].get<double>(), format) + "–" +
         num(s["p90"].get<double>(), format) + ")";
}

double med(const json& s) { return s["median"].get<double>(); }

const json* find_config(const json& terrain, const std::string& metric, double t) {
  for (const json& k : terrain["mrbsp"])
    if (k["metric"] == metric && k["threshold"].get<double>() == t && !k.value("occlusion", false)) return &k;
  return nullptr;
}

std::string pct(double share) { return num(100.0 * share, "%.3g") + "%"; }

void terrain_section(std::ostringstream& md, const json& results, const std::filesystem::path& dir) {
  if (!results.contains("terrain")) return;
  md << "## 1. Terrain flythrough\n\n"
     << "Per view: the full-resolution window drawn by plain VTK (ordinary mapper, depth test, every "
        "triangle, geometry uploaded once) and by the MRBSP at four thresholds of each LOD metric "
        "(screen-space error in pixels; projected box area in 250 t square pixels, so that t = 2 is its "
        "default of 500). Frame time = traversal + upload of the triangle list + draw. Image quality "
        "against Terravol's own full-resolution image of the same view. Figures are medians over the "
        "views (10th–90th percentile in brackets) of per-view medians over the repetitions.\n\n";
  std::vector<Series> tri, err;
  for (const json& t : results["terrain"]) {
    const std::string name = t["terrain"];
    md << "### " << name << " (" << t["window_cells"].get<int>() << " cells, " << t["levels"].get<int>() << " levels, "
       << t["views"].get<int>() << " views)\n\n";
    md << "| configuration | frame ms | traversal ms | draw ms | triangles | PSNR dB | SSIM | pixels > 8/255 | plain VTK / this |\n"
       << "|---|---|---|---|---|---|---|---|---|\n";
    const json& p = t["plain_vtk"];
    md << "| plain VTK, full resolution | " << spread(p["frame_ms"]) << " | – | – | " << num(p["triangles"].get<double>(), "%.0f")
       << " | " << num(med(p["psnr_against_reference"]), "%.1f") << " (against Terravol's) | – | – | 1 |\n"
     << "| Terravol, full resolution (the reference; triangles in the view frustum) | – | – | – | "
     << num(med(p["full_res_in_view"]), "%.0f") << " | – | – | – | – |\n";
    for (const char* metric : {"error", "area"}) {
      Series st{name + " " + metric, {}, {}, false}, se{name + " " + metric, {}, {}, false};
      for (double th : {0.5, 1.0, 2.0, 4.0}) {
        const json* k = find_config(t, metric, th);
        if (!k) continue;
        md << "| MRBSP " << metric << " " << num(th) << " | " << spread((*k)["frame_ms"]) << " | "
           << spread((*k)["traversal_ms"]) << " | " << spread((*k)["draw_ms"]) << " | "
           << num(med((*k)["triangles"]), "%.0f") << " | " << spread((*k)["psnr_db"], "%.1f") << " | "
           << num(med((*k)["ssim"]), "%.4f") << " | " << pct(med((*k)["share_over_8"])) << " | "
           << spread((*k)["plain_over_mrbsp"]) << " |\n";
        st.x.push_back(th);
        st.y.push_back(med((*k)["triangles"]));
        se.x.push_back(th);
        se.y.push_back(med((*k)["psnr_db"]));
      }
      if (!st.x.empty()) tri.push_back(st);
      if (!se.x.empty()) err.push_back(se);
    }
    for (const json& k : t["mrbsp"]) {
      if (!k.value("occlusion", false)) continue;
      md << "| MRBSP error " << num(k["threshold"].get<double>()) << ", occlusion on | " << spread(k["frame_ms"]) << " | "
         << spread(k["traversal_ms"]) << " (pass " << spread(k["occlusion_pass_ms"]) << ") | " << spread(k["draw_ms"])
         << " | " << num(med(k["triangles"]), "%.0f") << " | " << spread(k["psnr_db"], "%.1f") << " | "
         << num(med(k["ssim"]), "%.4f") << " | " << pct(med(k["share_over_8"])) << " | " << spread(k["plain_over_mrbsp"])
         << " |\n";
    }
    for (const json& k : t["mrbsp"]) {
      if (!k.value("occlusion", false)) continue;
      md << "\nOcclusion at " << num(k["threshold"].get<double>()) << " px: images byte-identical to culling off in "
         << pct(k["images_identical_to_off"].get<double>()) << " of the views; frame off / on "
         << num(k["frame_off_over_on"].get<double>(), "%.2f") << "x; regions tested "
         << num(med(k["occlusion_tested_nodes"]), "%.0f") << ".";
    }
    md << "\n";
    // Frame time along the path.
    ChartSpec along;
    along.title = "Frame time along the " + name + " flythrough";
    along.x_label = "view";
    along.y_label = "frame time (ms)";
    along.log_y = true;
    Series plain{"plain VTK, full resolution", {}, p["per_view_ms"].get<std::vector<double>>(), false};
    for (std::size_t i = 0; i < plain.y.size(); ++i) plain.x.push_back(static_cast<double>(i));
    along.series.push_back(plain);
    for (double th : {0.5, 1.0, 4.0}) {
      const json* k = find_config(t, "error", th);
      if (!k) continue;
      Series s{"MRBSP " + num(th) + " px", plain.x, (*k)["per_view_ms"].get<std::vector<double>>(), false};
      along.series.push_back(s);
    }
    const std::string file = "plot-frame-time-" + name + ".png";
    write_chart_png(dir / file, along);
    md << "![Frame time along the " << name << " path](" << file << ")\n\n";
  }
  if (tri.empty()) return;
  ChartSpec c1{"Triangles drawn against the threshold", "threshold t", "triangles per frame (median)", tri, true, true};
  write_chart_png(dir / "plot-triangles-threshold.png", c1);
  ChartSpec c2{"Image quality against the threshold", "threshold t", "PSNR against full resolution (dB, median)", err, true, false};
  write_chart_png(dir / "plot-error-threshold.png", c2);
  md << "![Triangles against threshold](plot-triangles-threshold.png)\n\n"
     << "![PSNR against threshold](plot-error-threshold.png)\n\n";
}

void translucency_section(std::ostringstream& md, const json& results) {
  if (!results.contains("translucency")) return;
  md << "## 2. Translucency, and 6. the pipeline users would otherwise build\n\n"
     << "Three overlapping RF volumes (two translucent isosurfaces each, and a slice), viewed from an "
        "orbit around them. The first four rows draw the same traversal (the same triangles): in the "
        "tree's order (bsp), by VTK's depth peeling with ParaView's 4 peels, with no limit on peels "
        "(exact: the reference), and by VTK 9.1's default (weighted blended OIT). The plain rows are "
        "what a ParaView or plain-VTK user would draw: the full-resolution lattice and undecimated "
        "isosurfaces and slice, geometry uploaded once, depth peeling with 4 peels or no limit; their "
        "error is against their own exact image. Frame times are medians over the views.\n\n";
  for (const json& t : results["translucency"]) {
    const json& m = t["merge"];
    md << "### " << t["terrain"].get<std::string>() << " (" << t["views"].get<int>() << " views, orbit "
       << num(t["orbit_km"].get<double>()) << " km)\n\n"
       << "Merged: " << m["input_triangles"].get<std::size_t>() << " triangles after decimation ("
       << m["undecimated_triangles"].get<std::size_t>() << " before) became " << m["tree_polygons"].get<std::size_t>()
       << " pieces in the tree; geometry " << num(m["geometry_ms"].get<double>(), "%.0f") << " ms, merge "
       << num(m["merge_ms"].get<double>(), "%.0f") << " ms, " << num(m["merged_bytes"].get<double>() / 1048576.0, "%.0f")
       << " MiB. Triangles per frame: " << num(med(t["triangles"]), "%.0f") << " (of them merged "
       << num(med(t["merged_triangles"]), "%.0f") << "); plain pipeline " << num(med(t["plain_triangles"]), "%.0f")
       << ".";
    if (t.contains("bsp_frame_parts_ms")) {
      const json& p = t["bsp_frame_parts_ms"];
      md << " The bsp frame (medians over the views): traversal " << num(med(p["traversal"]), "%.1f") << " ms, upload "
         << num(med(p["upload"]), "%.1f") << " ms, draw " << num(med(p["draw"]), "%.1f") << " ms.";
    }
    md << "\n\n"
       << "| drawing | frame ms | this / bsp | pixels > 3/255 from exact | PSNR dB |\n|---|---|---|---|---|\n";
    for (const char* name : {"bsp", "peel_exact", "peel4", "vtk_default", "plain_peel4", "plain_peel_exact"}) {
      md << "| " << name << " | " << spread(t["frame_ms"][name]) << " | "
         << (t["ratio_over_bsp"].contains(name) ? spread(t["ratio_over_bsp"][name]) : std::string("1")) << " | "
         << (t["share_over_3"].contains(name) ? pct(med(t["share_over_3"][name])) : std::string("0 (reference)")) << " | "
         << (t["psnr_db"].contains(name) ? num(med(t["psnr_db"][name]), "%.1f") : std::string("–")) << " |\n";
    }
    const json& r = t["responsiveness"];
    md << "\n**Responsiveness** (5): threshold change to finished frame " << spread(r["threshold_change_ms"], "%.0f")
       << " ms; slice move to finished frame " << spread(r["slice_move_ms"], "%.0f") << " ms (of which merge "
       << spread(r["slice_move_merge_ms"], "%.0f") << " ms); isovalue change to finished frame "
       << (r.contains("isovalue_change_ms") ? spread(r["isovalue_change_ms"], "%.0f") : std::string("–"))
       << " ms (of which merge "
       << (r.contains("isovalue_change_merge_ms") ? spread(r["isovalue_change_merge_ms"], "%.0f") : std::string("–"))
       << " ms); a slide of the tree by one level-0 cell with the volumes merged "
       << (r.contains("slide_with_volumes_ms") ? spread(r["slide_with_volumes_ms"], "%.0f") : std::string("–"))
       << " ms (of which merge "
       << (r.contains("slide_with_volumes_merge_ms") ? spread(r["slide_with_volumes_merge_ms"], "%.0f") : std::string("–"))
       << " ms; the window read ahead).\n\n";
    if (t.contains("responsiveness_parts_ms")) {
      const json& parts = t["responsiveness_parts_ms"];
      md << "| edit | geometry ms | merge ms | vertices ms | frame ms (traversal, upload, draw) | triangles drawn | idle tidy ms (slots) | triangles drawn after it |\n|---|---|---|---|---|---|---|---|\n";
      for (const char* edit : {"slice_move", "isovalue_change"}) {
        const std::string e(edit);
        if (!parts.contains(e + "_frame")) continue;
        md << "| " << e << " | " << spread(parts[e + "_geometry"], "%.0f") << " | " << spread(parts[e + "_merge"], "%.0f")
           << " | " << spread(parts[e + "_vertices"], "%.0f") << " | " << spread(parts[e + "_frame"], "%.0f") << " ("
           << num(med(parts[e + "_frame_traversal"]), "%.0f") << ", " << num(med(parts[e + "_frame_upload"]), "%.0f") << ", "
           << num(med(parts[e + "_frame_draw"]), "%.0f") << ") | ";
        if (parts.contains(e + "_tidy"))
          md << spread(parts[e + "_triangles"], "%.0f") << " | " << spread(parts[e + "_tidy"], "%.0f") << " ("
             << num(med(parts[e + "_tidy_slots"]), "%.0f") << ") | " << spread(parts[e + "_triangles_tidied"], "%.0f") << " |\n";
        else
          md << "– | – | – |\n";
      }
      md << "\n";
    }
  }
}

void hydrogen_section(std::ostringstream& md, const json& results) {
  if (!results.contains("hydrogen")) return;
  const json& h = results["hydrogen"];
  md << "**A closed surface:** hydrogen.vtk's isosurface at 0.02 ("
     << h["input_triangles"].get<std::size_t>()
     << " triangles) 1900 m up over the bundled DEM, from " << h["cameras"].get<std::size_t>()
     << " cameras: the tree stores " << spread(h["pieces_per_triangle"], "%.3f")
     << " pieces per input triangle; merge " << spread(h["merge_ms"], "%.0f") << " ms.\n\n";
}

void scaling_section(std::ostringstream& md, const json& results, const std::filesystem::path& dir) {
  if (!results.contains("scaling")) return;
  md << "## 3. Scaling\n\n"
     << "One view (2500 m above the window's centre, pitch −20°, heading 30°) of each terrain in its "
        "largest power-of-two window (at most 4096 cells), MRBSP at 1 px against plain VTK at full "
        "resolution.\n\n"
     << "| terrain | tiles | samples | tree MiB | MRBSP frame ms | MRBSP triangles | plain VTK frame ms | plain triangles |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  // The generated terrains as curves; real terrains as single points beside them.
  std::vector<Series> series;
  auto add = [&](const std::string& name, bool points, double x, double y) {
    for (Series& s : series)
      if (s.name == name) {
        s.x.push_back(x);
        s.y.push_back(y);
        return;
      }
    series.push_back({name, {x}, {y}, points});
  };
  for (const json& s : results["scaling"]) {
    const double samples = s["samples"].get<double>();
    const std::string name = s["terrain"];
    md << "| " << name << " | " << s["tiles"].get<int>() << " | " << num(samples, "%.0f")
       << " | " << num(s["tree_bytes"].get<double>() / 1048576.0, "%.0f") << " | " << spread(s["mrbsp_frame_ms"]) << " | "
       << s["mrbsp_triangles"].get<std::size_t>() << " | "
       << (s.contains("plain_frame_ms") ? spread(s["plain_frame_ms"]) : std::string("not drawn")) << " | "
       << (s.contains("plain_triangles") ? std::to_string(s["plain_triangles"].get<std::size_t>()) : std::string("–"))
       << " |\n";
    const bool generated = name.rfind("generated", 0) == 0;
    const std::string which = generated ? " (generated tiles)" : " (" + name + ")";
    add("MRBSP 1 px" + which, !generated, samples, med(s["mrbsp_frame_ms"]));
    if (s.contains("plain_frame_ms")) add("plain VTK, full resolution" + which, !generated, samples, med(s["plain_frame_ms"]));
  }
  ChartSpec c{"Frame time against terrain size (one view)", "DEM samples in the window", "frame time (ms)", series, true, true};
  write_chart_png(dir / "plot-scaling.png", c);
  md << "\n![Scaling](plot-scaling.png)\n\n";
}

void build_section(std::ostringstream& md, const json& results) {
  if (!results.contains("build")) return;
  md << "## 4. Build and slide\n\n"
     << "The tree of a 1024-cell window alone (no rendering, the lattice already read): build, and a "
        "slide by one coarsest cell (Wiley et al. 1997, section 4.3).\n\n"
     << "| terrain | samples | build ms | slide ms | build / slide | samples per second | bytes per sample (nodes + vertices) |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const json& b : results["build"]) {
    md << "| " << b["terrain"].get<std::string>() << " | " << b["samples"].get<std::size_t>() << " | "
       << spread(b["build_ms"], "%.1f") << " | " << spread(b["slide_ms"], "%.1f") << " | "
       << num(b["build_over_slide"].get<double>(), "%.2f") << " | "
       << num(b["build_samples_per_s"].get<double>() / 1e6, "%.2f") << " M | "
       << num(b["bytes_per_sample"]["total"].get<double>(), "%.0f") << " ("
       << num(b["bytes_per_sample"]["nodes"].get<double>(), "%.0f") << " + "
       << num(b["bytes_per_sample"]["vertices"].get<double>(), "%.0f") << ") |\n";
  }
  md << "\nThe viewer's frames through slides (issue 13: at most 5 ms more than the frames around them): the "
        "pipeline as `terravol view` runs it (the moved window read and shaded and the tree slid on a copy of "
        "the scene, on a worker thread; the copy swapped in and the vertices replaced at the next frame), terrain only, flying east 1000 m above the ground, a "
        "twentieth of a coarsest cell per frame, until two slides land. Frame wall times in ms: quiet (no slide "
        "under way), during (the worker reading, shading, copying the scene and sliding the copy), and the "
        "frames that land a slide, with their tree part (swapping the slid copy in) and vertex part, and what "
        "the copy and its slide took on the worker; then the same over the translucency suite's volumes, "
        "which each slide merges again.\n\n"
     << "| terrain | slides | quiet | during | landing | landing - quiet | tree | vertices | worker: copy, slide |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  const auto list = [](const json& a) {  // a list of milliseconds, "52, 51"
    std::string out;
    for (const json& x : a) out += (out.empty() ? "" : ", ") + num(x.get<double>(), "%.0f");
    return out;
  };
  for (const json& b : results["build"])
    for (const char* key : {"viewer_slides", "viewer_slides_volumes"}) {
      if (!b.contains(key)) continue;
      const json& v = b[key];
      md << "| " << b["terrain"].get<std::string>() << (std::string(key) == "viewer_slides" ? "" : " with its benchmark volumes")
         << " | " << v["slides"].get<std::size_t>() << " | ";
      if (!v.contains("quiet_frame_ms")) {
        md << "no slide (the window spans the mosaic east of its centre) | | | | | | |\n";
        continue;
      }
      md << spread(v["quiet_frame_ms"], "%.1f") << " | "
         << (v.contains("during_frame_ms") ? spread(v["during_frame_ms"], "%.1f") : std::string("-")) << " | "
         << list(v["landing_frame_ms"]) << " | +" << num(v["landing_over_quiet_ms"].get<double>(), "%.0f") << " | "
         << list(v["landing_tree_ms"]) << " | " << list(v["landing_vertices_ms"]) << " | ";
      if (v.contains("worker_copy_ms")) {
        for (std::size_t k = 0; k < v["worker_copy_ms"].size(); ++k) {
          md << (k ? "; " : "") << num(v["worker_copy_ms"][k].get<double>(), "%.0f") << ", "
             << num(v["worker_tree_ms"][k].get<double>(), "%.0f");
        }
      }
      md << " |\n";
    }
  md << "\n";
}

void exactness_section(std::ostringstream& md, const json& results) {
  if (!results.contains("exactness")) return;
  md << "## 7. Exactness against the independent reference (issue 11)\n\n"
     << "The real `terravol render --full-res --surface-triangles 0 --haze 0` of the issue's scene (two 8 km "
        "RF volumes, two translucent isosurfaces each) against a reference built without the tree, the "
        "volume layer or the renderer (`reference/`): the exported terrain, the isosurfaces extracted "
        "again from the `.vdb` files and placed by the reference's own scene frame and DEM reader, VTK "
        "depth peeling with no peel limit. Targets: at least 99.9% of pixels within 8/255 in every view, "
        "and `bsp` within 3/255 of its own `--order peel` on at least 99.9%. Peeling resolves depth in 24 "
        "bits between the near and far planes, so `bsp` and the peel are also drawn with ten times the "
        "default near plane; that pair counts when the tree's picture is then unchanged to the byte (the "
        "column gives the near plane used, and the default pair's figure). The images of each view "
        "(ours, the reference, the pixels off by more than 8/255 in red) are in `exactness/`.\n\n";
  for (const json& t : results["exactness"]) {
    md << "### " << t["terrain"].get<std::string>() << "\n\n"
       << "| view | camera | within 8/255 | within 3/255 | bsp vs peel within 3/255 | merged pieces drawn | "
          "reference triangles |\n|---|---|---|---|---|---|---|\n";
    for (const json& v : t["views"]) {
      const json& c = v["camera"];
      md << "| " << v["view"].get<std::string>() << " | " << num(c["lat"].get<double>(), "%.4f") << ", "
         << num(c["lon"].get<double>(), "%.4f") << ", " << num(c["alt"].get<double>(), "%.0f")
         << (c["agl"].get<bool>() ? " m AGL" : " m") << ", heading " << num(c["heading"].get<double>(), "%.0f")
         << ", pitch " << num(c["pitch"].get<double>(), "%.0f") << " | " << num(100.0 * v["within_8"].get<double>(), "%.3f")
         << "% | " << num(100.0 * v["within_3"].get<double>(), "%.3f") << "% | "
         << num(100.0 * v["bsp_vs_peel_within_3"].get<double>(), "%.3f") << "%"
         << (v.contains("peel_near_plane")
                 ? " (near " + num(v["peel_near_plane"].get<double>(), "%.2f") + " m; default " +
                       num(100.0 * v["bsp_vs_peel_within_3_default_near"].get<double>(), "%.3f") + "%)"
                 : std::string())
         << " | " << v["merged_drawn"].get<std::size_t>() << " | " << v["reference_volume_triangles"].get<std::size_t>() << " |\n";
    }
    md << "\n";
  }
}

void rf_section(std::ostringstream& md, const json& results) {
  if (!results.contains("rf")) return;
  const json& r = results["rf"];
  md << "## 8. RF volumes\n\n"
     << "A 20 km box at 3\" with " << r["heights"].get<int>() << " receiver heights (10..310 m, "
     << num(r["points"].get<double>() / 1e6, "%.2f") << " M points) over " << r["terrain"].get<std::string>()
     << ", transmitter 30 m above Salt Lake City at 900 MHz: the built-in Longley-Rice ITM and Deygout models "
        "(`compute_rf`, both cores, tiles read afresh) against SPLAT!'s own ITM (`splat -olditm`) run once per "
        "height, as `terravol splat-volume` does (timed at "
     << r["splat_heights"].get<int>() << " heights; its volume is its preparation plus " << r["heights"].get<int>()
     << " times the median per height).\n\n"
     << "| | wall s | CPU s |\n|---|---|---|\n"
     << "| built-in ITM | " << spread(r["wall_s"]["itm"]) << " | " << spread(r["cpu_s"]["itm"]) << " |\n"
     << "| built-in ITM, the disc only (`--disc`) | " << spread(r["wall_s"]["itm_disc"]) << " | "
     << spread(r["cpu_s"]["itm_disc"]) << " |\n"
     << "| built-in Deygout | " << spread(r["wall_s"]["deygout"]) << " | " << spread(r["cpu_s"]["deygout"]) << " |\n";
  if (r.contains("splat_volume_wall_s")) {
    md << "| SPLAT! -olditm, per height | " << spread(r["wall_s"]["splat_per_height"]) << " | "
       << spread(r["cpu_s"]["splat_per_height"]) << " |\n"
       << "| SPLAT! -olditm, the volume | " << num(r["splat_volume_wall_s"].get<double>()) << " | "
       << num(r["splat_volume_cpu_s"].get<double>()) << " |\n\n"
       << "SPLAT! / built-in ITM: " << num(r["splat_over_itm_wall"].get<double>(), "%.1f") << "x in wall time, "
       << num(r["splat_over_itm_cpu"].get<double>(), "%.1f") << "x in CPU time; over the same disc, "
       << num(r["splat_over_itm_disc_wall"].get<double>(), "%.1f") << "x and "
       << num(r["splat_over_itm_disc_cpu"].get<double>(), "%.1f") << "x.\n";
  }
  md << "\n";
}

void objects_section(std::ostringstream& md, const json& results) {
  if (!results.contains("objects")) return;
  md << "## 9. Objects on the terrain\n\n"
     << "Instances of assimp-testmodels' models (the glTF milk truck, 3,624 triangles; the PLY Wuson, 3,732) over "
        "N44W072 in a 512-cell window, each instance merged into the tree in the level its projected error asks "
        "for (2 px; colour cubes below a pixel), against the same pipeline with every instance at full resolution "
        "(its own tree) and against plain VTK drawing the full-resolution lattice with every instance at full "
        "resolution (4 peels). Frame times include choosing the levels; \"on arrival\" is the first frame of a "
        "view, which merges again the instances whose level changed. \"Objects' part\" is what the objects add to "
        "the terrain's frame (the same pipeline without them, measured beside; medians over the views, their ratio), "
        "the figure the paper's section 7.2 compares (its scene held the Volkswagens alone).\n\n"
     << "| layout | instances | LOD frame ms | full-res frame ms | full / LOD | objects' part: full / LOD | plain VTK / LOD | "
        "PSNR dB (min) | object triangles LOD / full | on arrival ms |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const json& o : results["objects"]) {
    md << "| " << o["layout"].get<std::string>() << " | " << o["instances"].get<std::size_t>() << " | "
       << spread(o["lod_frame_ms"]) << " | " << spread(o["full_frame_ms"]) << " | "
       << num(med(o["full_over_lod"]), "%.2f") << "x | " << num(o["objects_added_full_over_lod"].get<double>(), "%.2f") << "x ("
       << spread(o["objects_added_full_ms"]) << " / " << spread(o["objects_added_lod_ms"]) << " ms) | "
       << num(med(o["plain_over_lod"]), "%.1f") << "x | "
       << num(med(o["psnr_db"]), "%.1f") << " (" << num(o["psnr_db"]["min"].get<double>(), "%.1f") << ") | "
       << num(med(o["object_triangles_lod"]), "%.0f") << " / " << o["full_triangles"].get<std::size_t>() << " | "
       << spread(o["merge_on_arrival_ms"]) << " |\n";
  }
  md << "\nLevels (triangles, Hausdorff distance to the full model in model units):\n\n";
  for (const json& m : results["objects"].back()["models"]) {
    md << "-";
    for (const json& l : m["levels"])
      md << " " << l["triangles"].get<std::size_t>() << " (" << num(l["hausdorff"].get<double>(), "%.3f") << ")";
    md << "; all levels / the full model's bytes "
       << num(m["bytes_all_levels"].get<double>() / m["bytes_full"].get<double>(), "%.2f") << "\n";
  }
  md << "\n";
}

void density_section(std::ostringstream& md, const json& results) {
  if (!results.contains("density")) return;
  const json& d = results["density"];
  md << "## 12. Densities: the colour-cube octree\n\n"
     << "A 6 km path-loss volume over the bundled DEM (N45E006; 6 arc seconds, 0-2000 m every 100 m) and the same "
        "lattice refined 2x and 4x per axis, drawn as a density (" << d["transfer"].get<std::string>() << ") in the "
        "tree's order: the colour-cube octree at epsilon 1 px against every voxel cell (the same path, every leaf in "
        "the frustum; either left out above 3 million cells), from 1.75 to 14 volume radii. Frame: the octree's refinement, "
        "the traversal that orders its cells with the terrain, upload and draw.\n\n"
     << "| lattice | radii | octree ms | cells (per level from the leaves) | every cell ms | every cell / octree | "
        "every-cell cells |\n|---|---|---|---|---|---|---|\n";
  for (const json& s : d["series"]) {
    for (const json& v : s["views"]) {
      std::string levels;
      if (v.contains("octree_cells_per_level"))
        for (const json& n : v["octree_cells_per_level"]) levels += (levels.empty() ? "" : " ") + std::to_string(n.get<std::size_t>());
      md << "| " << s["factor"].get<int>() << "x | " << num(v["radii"].get<double>()) << " | "
         << (v.contains("octree_ms") ? num(v["octree_ms"].get<double>(), "%.1f") : std::string("not drawn")) << " | " << v["octree_cells"].get<std::size_t>() << " (" << levels << ") | "
         << (v.contains("every_ms") ? num(v["every_ms"].get<double>(), "%.1f") : std::string("not drawn")) << " | "
         << (v.contains("every_over_octree") ? num(v["every_over_octree"].get<double>(), "%.2f") + "x" : std::string("-"))
         << " | " << v["every_cells"].get<std::size_t>() << " |\n";
    }
  }
  md << "\nThe default RF volume (scripts/setup-and-run.sh) from the default scene's camera:\n\n"
     << "| scene | frame ms | transfer change to frame ms | cells | faces | refine / order / draw ms | "
        "against the ray marcher (mean, 99th pct) | bsp vs exact peel within 3/255 (cubes up to 64 px) |\n|---|---|---|---|---|---|---|---|\n";
  for (const json& v : d["default_volume"]) {
    md << "| " << (v["surfaces"].get<bool>() ? "with isosurfaces and slice" : "density alone") << " | "
       << spread(v["frame_ms"]) << " | " << spread(v["transfer_change_to_frame_ms"]) << " | "
       << v["cells"].get<std::size_t>() << " | " << v["faces"].get<std::size_t>() << " | "
       << num(v["refine_ms"].get<double>(), "%.0f") << " / " << num(v["order_ms"].get<double>(), "%.0f") << " / "
       << num(v["draw_ms"].get<double>(), "%.0f") << " | "
       << (v.contains("reference_mean_error") ? num(v["reference_mean_error"].get<double>(), "%.2f") + ", " +
                                                    num(v["reference_p99_error"].get<double>(), "%.0f") + " /255"
                                              : std::string("-"))
       << " | " << (v.contains("bsp_vs_peel_within_3") ? pct(v["bsp_vs_peel_within_3"].get<double>()) : std::string("-"))
       << " |\n";
  }
  md << "\n";
}

void lowalt_section(std::ostringstream& md, const json& results) {
  if (!results.contains("lowalt")) return;
  md << "## 10. Low altitude: occlusion culling and coherence\n\n"
     << "Low views 100-500 m above the ground in valleys and toward ridges, and high views (3000-8000 m) for "
        "the culling's overhead; per view the same LOD choice drawn with coverage-mask occlusion culling off, "
        "then on. Hidden: triangles of the off frame that show in no pixel of its item buffer (each triangle "
        "drawn in a colour of its own, in the frame's order); hidden culled: the share of those the "
        "occlusion pass left out when it runs (the view traversed again with the pass forced: "
        "occlusion_adaptive leaves a pass that does not pay out of the next 8 frames; pass ran: the share of "
        "timed frames it ran in, probe: its time in the warm-up frames it ran in). Crack pixels: the terrain pixels whose front triangle is a crack fill. "
        "Medians over the views (10th-90th percentile in brackets).\n\n";
  for (const json& t : results["lowalt"]) {
    md << "### " << t["terrain"].get<std::string>() << " (" << t["low_views"].get<int>() << " low views, "
       << t["high_views"].get<int>() << " high)\n\n"
       << "| views | px | frame ms off | frame ms on | off / on (per view) | off / on (medians) | images identical | "
          "pass ran | pass ms (probe) | triangles off | triangles on | hidden of drawn | hidden culled | visible culled | crack pixels |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const json& k : t["occlusion"]) {
      md << "| " << k["views"].get<std::string>() << " | " << num(k["threshold_px"].get<double>()) << " | "
         << spread(k["off"]["frame_ms"]) << " | " << spread(k["on"]["frame_ms"]) << " | " << spread(k["off_over_on"])
         << " | " << num(k["off_over_on_of_medians"].get<double>()) << " | " << pct(k["images_identical"].get<double>())
         << " | " << pct(k["pass_ran_share"].get<double>()) << " | " << spread(k["probe_pass_ms"]) << " | "
         << num(med(k["off"]["triangles"]), "%.0f") << " | "
         << num(med(k["on"]["triangles"]), "%.0f") << " | " << pct(med(k["hidden_share_of_drawn"])) << " | "
         << pct(med(k["hidden_culled_share"])) << " | " << num(k["visible_culled"].get<double>(), "%.0f") << " | "
         << pct(med(k["crack_pixel_share"])) << " |\n";
    }
    const json& f = t["flight"];
    md << "\nA " << f["frames"].get<int>() << "-frame low flight at 1 px (unculled frame "
       << spread(f["off_frame_ms"]) << " ms): occlusion node tests per frame\n\n"
       << "| coherence | queries per frame (tests and samples) | skipped per frame | queries / testing every node | pass ms | images identical |\n"
       << "|---|---|---|---|---|---|\n";
    for (const char* name : {"every_node", "update", "conservative"}) {
      const json& m = f[name];
      md << "| " << name << " | " << spread(m["visibility_queries"], "%.0f") << " | " << spread(m["skipped_tests"], "%.0f")
         << " | " << pct(m["tests_over_every_node"].get<double>()) << " | " << spread(m["pass_ms"]) << " | "
         << pct(m["images_identical"].get<double>()) << " |\n";
    }
    md << "\n";
  }
}

void aa_section(std::ostringstream& md, const json& results) {
  if (!results.contains("aa")) return;
  const json& a = results["aa"];
  md << "## 11. Antialiasing: the coverage-mask tiler against supersampling (issue 14)\n\n"
     << "The tiler (`--renderer tiler --aa N`: the tree's front-to-back order tiled into a coverage pyramid "
        "of N x N samples a pixel, Greene 1996) and VTK's box-filtered supersampling (`fly --samples`: the "
        "frame drawn f times larger, read back and averaged down), side by side per view, each image against "
        "a 16 x 16-sample reference (VTK, drawn 16 times larger in tiles and averaged). Frame: traversal, "
        "draw, and for VTK the upload, read-back and filter. Medians over the views (10th-90th percentile "
        "in brackets).\n\n";
  for (const char* key : {"terrain_views", "volume_views"}) {
    if (!a.contains(key)) continue;
    const json& p = a[key];
    md << "### " << p["part"].get<std::string>() << ", " << p["width"].get<int>() << "x" << p["height"].get<int>()
       << " (" << p["views"].get<int>() << " views, " << num(med(p["triangles"]), "%.0f") << " triangles; reference "
       << p["reference"]["tiles"].get<int>() << " tiles of " << p["reference"]["tile_samples"][0].get<int>() << "x"
       << p["reference"]["tile_samples"][1].get<int>() << ")\n\n"
       << "| configuration | frame ms | PSNR against the reference (dB) |\n|---|---|---|\n";
    for (const auto& [name, ms] : p["frame_ms"].items()) {
      md << "| " << name << " | " << spread(ms) << " | "
         << (p["psnr_db"].contains(name) ? spread(p["psnr_db"][name]) : std::string("")) << " |\n";
    }
    md << "\n| figure | target | measured |\n|---|---|---|\n";
    if (p["psnr_db"].contains("tiler_64")) md << "| tiler 8x8 against the reference | >= 40 dB | " << spread(p["psnr_db"]["tiler_64"]) << " dB |\n";
    if (!p["ratios"]["vtk_16_over_tiler_16"].is_null())
      md << "| VTK 16 samples / tiler 4x4, time | >= 3x | " << spread(p["ratios"]["vtk_16_over_tiler_16"]) << " |\n";
    if (!p["ratios"]["tiler_64_over_vtk_16"].is_null())
      md << "| tiler 8x8 / VTK 16 samples, time | <= 1x | " << spread(p["ratios"]["tiler_64_over_vtk_16"]) << " |\n";
    if (!p["ratios"]["tiler_64_over_vtk_1"].is_null())
      md << "| tiler 8x8 / VTK without antialiasing, time | <= 2x | " << spread(p["ratios"]["tiler_64_over_vtk_1"]) << " |\n";
    if (p.contains("psnr_db_tiler_64_vs_vtk_16"))
      md << "| tiler 8x8 against VTK at 16 samples | >= 35 dB (1920x1080, volumes) | " << spread(p["psnr_db_tiler_64_vs_vtk_16"]) << " dB |\n";
    if (!p["ratios"]["vtk_64_over_tiler_64"].is_null())
      md << "| VTK 64 samples / tiler 8x8, time | (Greene: 5.3x over a painter's scan converter) | " << spread(p["ratios"]["vtk_64_over_tiler_64"]) << " |\n";
    const json& f = p["tiler_64_figures"];
    md << "\nThe tiler at 8x8 per output pixel: " << spread(f["cells_visited_per_pixel"]) << " pyramid cells visited "
       << "(Greene's figure 3: 1.01 for the polygons), " << spread(f["fragments_per_pixel"]) << " fragments, "
       << spread(f["shading_points_per_pixel"]) << " shading points.";
    if (p.contains("occlusion")) {
      const json& o = p["occlusion"];
      md << " With the tree's occlusion pass at sample resolution (section 5.2): " << spread(o["culled_leaves"], "%.0f")
         << " drawn cells culled, images identical in " << pct(o["images_identical"].get<double>())
         << " of the views (least " << pct(o["images_identical_min"].get<double>()) << "), time without / with "
         << spread(o["tiler_64_over_tiler_64_occlusion"]) << ".";
    }
    md << "\n\n";
  }
}

}  // namespace

std::string headline(const json& results) {
  std::ostringstream h;
  if (results.contains("aa") && results["aa"].contains("terrain_views")) {
    const json& p = results["aa"]["terrain_views"];
    h << "aa, " << p["part"].get<std::string>() << ": tiler 8x8 " << num(med(p["psnr_db"]["tiler_64"]), "%.1f")
      << " dB against 16x16, VTK 16 samples / tiler 4x4 " << num(med(p["ratios"]["vtk_16_over_tiler_16"]), "%.2f")
      << "x, tiler 8x8 / VTK 16 samples " << num(med(p["ratios"]["tiler_64_over_vtk_16"]), "%.2f")
      << "x, tiler 8x8 / VTK 1 sample " << num(med(p["ratios"]["tiler_64_over_vtk_1"]), "%.2f") << "x\n";
  }
  if (results.contains("terrain"))
    for (const json& t : results["terrain"])
      h << "full-res VTK / MRBSP at 1 px, " << t["terrain"].get<std::string>() << ": "
        << num(t["headline_ratio_1px"].get<double>(), "%.1f") << "x\n";
  if (results.contains("translucency"))
    for (const json& t : results["translucency"]) {
      const std::string n = t["terrain"];
      h << "translucency " << n << ": exact peeling / bsp " << num(med(t["ratio_over_bsp"]["peel_exact"]), "%.2f")
        << "x, 4 peels / bsp " << num(med(t["ratio_over_bsp"]["peel4"]), "%.2f") << "x, VTK default / bsp "
        << num(med(t["ratio_over_bsp"]["vtk_default"]), "%.2f") << "x; pixels > 3/255 from exact: bsp "
        << pct(med(t["share_over_3"]["bsp"])) << ", 4 peels " << pct(med(t["share_over_3"]["peel4"]))
        << ", VTK default " << pct(med(t["share_over_3"]["vtk_default"])) << "\n";
      h << "depth-peeled full-res VTK / Terravol, " << n << ": 4 peels "
        << num(med(t["ratio_over_bsp"]["plain_peel4"]), "%.1f") << "x, exact "
        << num(med(t["ratio_over_bsp"]["plain_peel_exact"]), "%.1f") << "x\n";
    }
  if (results.contains("scaling") && results["scaling"].size() >= 2) {
    const json& a = results["scaling"].front();
    const json& b = results["scaling"].back();
    h << "scaling " << a["terrain"].get<std::string>() << " -> " << b["terrain"].get<std::string>() << " ("
      << num(b["samples"].get<double>() / a["samples"].get<double>(), "%.1f") << "x the samples): MRBSP frame time "
      << num(med(b["mrbsp_frame_ms"]) / med(a["mrbsp_frame_ms"]), "%.2f") << "x";
    if (a.contains("plain_frame_ms") && b.contains("plain_frame_ms"))
      h << ", plain VTK " << num(med(b["plain_frame_ms"]) / med(a["plain_frame_ms"]), "%.1f") << "x";
    h << "\n";
  }
  if (results.contains("exactness"))
    for (const json& t : results["exactness"]) {
      h << "exactness " << t["terrain"].get<std::string>() << ": pixels within 8/255 of the independent reference, "
        << "lowest view " << num(100.0 * t["min_within_8"].get<double>(), "%.2f") << "%";
      for (const json& v : t["views"])
        if (v["view"] == "inside" || v["view"] == "outside")
          h << ", " << v["view"].get<std::string>() << " " << num(100.0 * v["within_8"].get<double>(), "%.3f") << "%";
      h << "; bsp against its own peel within 3/255, lowest view "
        << num(100.0 * t["min_bsp_vs_peel_within_3"].get<double>(), "%.3f") << "%\n";
    }
  if (results.contains("lowalt"))
    for (const json& t : results["lowalt"]) {
      const json& low = t["occlusion"][0];
      const json& high = t["occlusion"][2];
      h << "low altitude " << t["terrain"].get<std::string>() << " at 1 px: occlusion off / on "
        << num(med(low["off_over_on"]), "%.2f") << "x (high views " << num(med(high["off_over_on"]), "%.2f")
        << "x), hidden culled " << pct(med(low["hidden_culled_share"])) << ", images identical "
        << pct(low["images_identical"].get<double>()) << "; flight tests / every node: update "
        << pct(t["flight"]["update"]["tests_over_every_node"].get<double>()) << ", conservative "
        << pct(t["flight"]["conservative"]["tests_over_every_node"].get<double>()) << "\n";
    }
  if (results.contains("build"))
    for (const json& b : results["build"])
      h << "slide / build, " << b["terrain"].get<std::string>() << ": 1/"
        << num(b["build_over_slide"].get<double>(), "%.1f") << "\n";
  if (results.contains("rf") && results["rf"].contains("splat_over_itm_wall"))
    h << "31-height ITM volume, SPLAT! -olditm per height / built-in: "
      << num(results["rf"]["splat_over_itm_wall"].get<double>(), "%.1f") << "x wall, "
      << num(results["rf"]["splat_over_itm_cpu"].get<double>(), "%.1f") << "x CPU (the disc: "
      << num(results["rf"]["splat_over_itm_disc_wall"].get<double>(), "%.1f") << "x wall, "
      << num(results["rf"]["splat_over_itm_disc_cpu"].get<double>(), "%.1f") << "x CPU)\n";
  if (results.contains("density")) {
    const json& d = results["density"];
    const json& first = d["series"][0]["views"];
    h << "density: every cell / octree at 1.75 and 14 radii "
      << (first[0].contains("every_over_octree") ? num(first[0]["every_over_octree"].get<double>(), "%.2f") : std::string("-")) << "x and "
      << (first[3].contains("every_over_octree") ? num(first[3]["every_over_octree"].get<double>(), "%.2f") : std::string("-"))
      << "x; default volume frame " << num(med(d["default_volume"][0]["frame_ms"]), "%.0f") << " ms, transfer change to frame "
      << num(med(d["default_volume"][0]["transfer_change_to_frame_ms"]), "%.0f") << " ms\n";
  }
  if (results.contains("objects"))
    for (const json& o : results["objects"])
      h << "objects " << o["layout"].get<std::string>() << ": full-res / LOD frame time "
        << num(med(o["full_over_lod"]), "%.2f") << "x, plain VTK / LOD " << num(med(o["plain_over_lod"]), "%.1f")
        << "x, PSNR against full resolution " << num(med(o["psnr_db"]), "%.1f") << " dB; the objects' part of the "
        << "frame: full-res / LOD " << num(o["objects_added_full_over_lod"].get<double>(), "%.2f") << "x\n";
  return h.str();
}

void write_report(const json& results, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::ostringstream md;
  const json& m = results["machine"];
  md << "# Benchmarks\n\n"
     << (results["quick"].get<bool>() ? "A quick run (`bench/run --quick`): fewer views and repetitions.\n\n" : "")
     << "Run on " << results["date"].get<std::string>() << ", " << m["cpu"].get<std::string>() << ", "
     << m["cores"].get<int>() << " cores, " << num(m["memory_gib"].get<double>(), "%.0f") << " GiB, "
     << m["renderer"].get<std::string>() << ", " << results["width"].get<int>() << "x" << results["height"].get<int>()
     << " offscreen; " << results["repeats"].get<int>() << " timed repetitions per frame after a warm-up. "
     << "Every comparison was measured side by side in this one run. Total time "
     << num(results["seconds"].get<double>() / 60.0, "%.1f") << " min. Made by `" << results["command"].get<std::string>()
     << "`; the figures are in `results.json`.\n\n"
     << "## Headline\n\n```\n" << headline(results) << "```\n\n";
  terrain_section(md, results, dir);
  translucency_section(md, results);
  hydrogen_section(md, results);
  scaling_section(md, results, dir);
  build_section(md, results);
  exactness_section(md, results);
  rf_section(md, results);
  objects_section(md, results);
  lowalt_section(md, results);
  aa_section(md, results);
  density_section(md, results);
  const std::string text = md.str();
  app::output::write_file_atomically(dir / "report.md", std::vector<std::uint8_t>(text.begin(), text.end()), true);
  const std::string j = results.dump(1);
  app::output::write_file_atomically(dir / "results.json", std::vector<std::uint8_t>(j.begin(), j.end()), true);
}

}  // namespace terravol::bench
