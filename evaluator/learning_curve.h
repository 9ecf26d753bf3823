// Learning-curve plots as standalone SVG documents (drawn with plot.h): evaluation mean as a line
// with a shaded band of plus/minus one std, a dashed horizontal goal line, axes with tick labels
// and titles.
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace rl::evaluator {

/// One evaluated checkpoint on the curve.
struct CurvePoint {
  double x = 0;     // env steps or wall seconds
  double mean = 0;  // mean return
  double std = 0;   // std of the returns
  // Observed range of the returns: the band is clipped to it (a band above the highest return
  // an episode can reach would mislead). NaN: not clipped.
  double min = std::nan("");
  double max = std::nan("");
};

/// How the x axis is labelled.
enum class XAxisKind {
  kCount,    // a count (env steps): ticks as 0, 50k, 1.5M
  kSeconds,  // a duration: ticks in seconds, minutes or hours, whichever suits the range
};

struct CurveStyle {
  std::string title;    // drawn above the plot
  std::string x_label;  // axis title; for kSeconds the unit is appended, e.g. " (min)"
  std::string y_label = "evaluation return";
  XAxisKind x_kind = XAxisKind::kCount;
  double goal = 0;  // dashed horizontal line; not drawn when not finite
  int width = 720;  // pixels
  int height = 380;
};

/// A second line over the curve, without a band (e.g. the means of the checkpoints' ensembles).
struct CurveOverlay {
  std::string label;               // its legend entry
  std::vector<CurvePoint> points;  // their means are drawn; std, min and max are not
};

/// Renders the curve (points are sorted by x; points with a non-finite x, mean or std are left
/// out) and the overlay's line, if it has points, in another colour. With no points the plot
/// shows its axes and a "no checkpoint scored yet" note.
std::string RenderLearningCurveSvg(std::vector<CurvePoint> points, const CurveStyle& style,
                                   CurveOverlay overlay = {});

}  // namespace rl::evaluator
