#pragma once
// The insight windows of the GUI (A/B compare, predicted vs measured with
// hot nodes and traversal modes, SAH explainer, tree view, scenarios): their
// state, their background jobs, and the script commands that drive them
// (scenario, dump-scenario, dump-insight). gui_main.cpp owns one and calls
// draw() once per frame.
#include <nlohmann/json.hpp>
#include <optional>

#include "core/analysis/insight/sah_explainer.h"
#include "ui/app/app_state.h"
#include "ui/app/insight_jobs.h"
#include "ui/app/scenarios.h"
#include "ui/app/script.h"
#include "ui/panels/insight_panels.h"

namespace accelviz {

class InsightViews {
 public:
  void draw(AppState& app, const panels::PanelLayout& layout);
  /// scenario, dump-scenario, dump-insight.
  ScriptHost::Status execute(AppState& app, const ScriptCommand& c);
  /// A job is running (keep frames coming).
  bool busy();

 private:
  void request_insight(AppState& app);
  const SplitExplanation* explanation(const AppState& app, std::string& note);
  nlohmann::json insight_json(const AppState& app);

  panels::ABPanelState ab_;
  AsyncJob<ABResult> ab_job_;
  AsyncJob<ViewInsight> insight_job_;
  panels::ExplainerState explainer_;
  panels::ScenarioPanelState scenario_;
  ScenarioJob scenario_job_;
  bool script_insight_requested_ = false;

  // The explanation shown, for (structure, node, buckets).
  const BuiltStructure* explained_for_ = nullptr;
  std::uint32_t explained_node_ = 0;
  int explained_buckets_ = 0;
  std::optional<SplitExplanation> explanation_;
  std::string explanation_note_;
};

}  // namespace accelviz
