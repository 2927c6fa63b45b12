#include "tools/track_picture.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tools/canvas.h"
#include "tools/fixed_text.h"
#include "tools/picture_png.h"

namespace hpose::tools {
namespace {

constexpr int kMargin = 20;
constexpr int kTopViewSize = kTrackPictureHeight - 2 * kMargin - 20;  // below the title.
constexpr double kViewMarginM = 0.4;
constexpr double kMinViewSpanM = 2.0;

const Bgr kBackground(30, 30, 30);
const Bgr kGrid(58, 58, 58);
const Bgr kLabel(150, 150, 150);
const Bgr kText(230, 230, 230);
const Bgr kAmbiguous(40, 160, 255);  // BGR orange.
const Bgr kFoundStrip(90, 180, 90);
const Bgr kMissedStrip(70, 70, 190);
const Bgr kTruth(150, 225, 150);  // BGR pale green.

void Text(Canvas& img, const std::string& s, Px at, double scale, const Bgr& c) {
  img.Text(s, at, scale, c, 1, LineKind::kSmooth);
}

// From blue (t = 0, the first frame) to red (t = 1, the last), through violet.
Bgr TimeColour(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return Bgr(255 * (1.0 - t) + 50 * t, 70, 50 * (1.0 - t) + 255 * t);
}

// The frames' times as shares of the time axis: 0 at the earliest, 1 at the latest.
struct TimeAxis {
  double t0 = 0.0, t1 = 0.0;
  // Where `t` lies along the axis, `flat` when every frame has the same time.
  double Share(double t, double flat) const { return t1 > t0 ? (t - t0) / (t1 - t0) : flat; }
  Bgr Colour(const TrackPoint& p) const { return TimeColour(Share(p.time_s, 0.0)); }
};

// A grid step of 0.5, 1, 2, 5, ... metres for a span, about 4 to 10 lines.
double GridStep(double span) {
  for (double step : {0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0}) {
    if (span / step <= 10.0) return step;
  }
  return 200.0;
}

void DrawTopView(Canvas& img, const TrackTopView& v, const std::vector<TrackPoint>& track,
                 const TimeAxis& time, int found) {
  const PxBox panel{v.left, v.top, v.size, v.size};
  Canvas view = img.Region(panel);  // clips what is drawn to the panel.
  const auto px = [&](double x, double y) { return Px(v.Col(y) - v.left, v.Row(x) - v.top); };
  const double span = v.size / v.px_per_m;
  const double step = GridStep(span);
  const double half = 0.5 * span;
  // The y labels run along the bottom edge; an x line too close to it keeps no label.
  constexpr int kBottomLabelBand = 18;
  for (double x = std::floor((v.x0 - half) / step) * step; x <= v.x0 + half; x += step) {
    view.Line(px(x, v.y0 + half), px(x, v.y0 - half), kGrid, 1);
    const Px at = px(x, v.y0 + half) + Px(4, -4);
    if (at.y > v.size - kBottomLabelBand) continue;
    Text(view, FormatNumber("x %g m", std::abs(x) < 1e-9 ? 0.0 : x), at, 0.4, kLabel);
  }
  for (double y = std::floor((v.y0 - half) / step) * step; y <= v.y0 + half; y += step) {
    view.Line(px(v.x0 + half, y), px(v.x0 - half, y), kGrid, 1);
    Text(view, FormatNumber("y %g", std::abs(y) < 1e-9 ? 0.0 : y), px(v.x0 - half, y) + Px(3, -6),
         0.4, kLabel);
  }
  view.Marker(px(0, 0), kText, MarkerShape::kTriangleUp, 16, 2);
  Text(view, "sensor", px(0, 0) + Px(12, 4), 0.45, kText);

  // The true path beneath, a broad band the estimated path runs along where it is right, between
  // frames with a truth one after the other, a dot at each.
  for (size_t i = 0; i < track.size(); ++i) {
    if (!track[i].has_truth) continue;
    const Px at = px(track[i].truth.x, track[i].truth.y);
    if (i > 0 && track[i - 1].has_truth) {
      view.Line(px(track[i - 1].truth.x, track[i - 1].truth.y), at, kTruth, 4, LineKind::kSmooth);
    }
    view.Circle(at, 3, kTruth, -1);
  }
  // The path, between frames found one after the other.
  for (size_t i = 1; i < track.size(); ++i) {
    if (!track[i - 1].found || !track[i].found) continue;
    view.Line(px(track[i - 1].pose.x, track[i - 1].pose.y), px(track[i].pose.x, track[i].pose.y),
              time.Colour(track[i]), 2, LineKind::kSmooth);
  }
  // Every found pose as a dot, and its heading every few of them (about 40 arrows at most).
  const int every = std::max(1, found / 40);
  const double arrow_m = std::max(0.15, 0.04 * span);
  int k = 0;
  for (const TrackPoint& p : track) {
    if (!p.found) continue;
    const Px at = px(p.pose.x, p.pose.y);
    view.Circle(at, 2, time.Colour(p), -1, LineKind::kSmooth);
    if (k++ % every == 0) {
      const Px tip = px(p.pose.x + arrow_m * std::cos(p.pose.theta),
                        p.pose.y + arrow_m * std::sin(p.pose.theta));
      view.ArrowedLine(at, tip, p.heading_ambiguous ? kAmbiguous : time.Colour(p), 1,
                       LineKind::kSmooth, 0.3);
    }
  }
  const auto first = std::find_if(track.begin(), track.end(), [](auto& p) { return p.found; });
  const auto last = std::find_if(track.rbegin(), track.rend(), [](auto& p) { return p.found; });
  if (first != track.end()) {
    view.Circle(px(first->pose.x, first->pose.y), 7, TimeColour(0.0), 2, LineKind::kSmooth);
    const Px end = px(last->pose.x, last->pose.y);
    view.Rectangle(end - Px(6, 6), end + Px(6, 6), TimeColour(1.0), 2);
  } else {
    // Centred in the panel's upper quarter, on the background, clear of the sensor below.
    const std::string note = "no humanoid found in any frame";
    const TextBox box = view.MeasureText(note, 0.7, 1);
    const int baseline = box.baseline;
    const Px at((v.size - box.width) / 2, v.size / 4);
    view.Rectangle(at + Px(-8, baseline + 6), at + Px(box.width + 8, -box.height - 8), kBackground,
                   kFilled);
    Text(view, note, at, 0.7, Bgr(120, 120, 255));
  }
  img.Rectangle(panel, kLabel, 1);
}

// What the charts show of a frame.
struct Series {
  const char* name;
  double (*value)(const TrackPoint&);
  bool heading;  // degrees: shown over [-180, 180], not joined across the wrap.
  // The same of the frame's truth (where it has one), or nullptr for a value without a truth.
  double (*truth)(const TrackPoint&);
};
constexpr Series kSeries[] = {
    {"x (m)", [](const TrackPoint& p) { return p.pose.x; }, false,
     [](const TrackPoint& p) { return p.truth.x; }},
    {"y (m)", [](const TrackPoint& p) { return p.pose.y; }, false,
     [](const TrackPoint& p) { return p.truth.y; }},
    {"heading (deg)", [](const TrackPoint& p) { return RadToDeg(p.pose.theta); }, true,
     [](const TrackPoint& p) { return RadToDeg(p.truth.theta); }},
    {"score", [](const TrackPoint& p) { return p.score; }, false, nullptr},
};

// One chart of a value against time: its frame, the range, and the samples of the frames found
// joined while they follow one another.
void DrawChart(Canvas& img, const PxBox& box, const Series& series,
               const std::vector<TrackPoint>& track, const TimeAxis& time) {
  const auto value = series.value;
  const auto truth = series.truth;
  const bool wraps = series.heading;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const TrackPoint& p : track) {
    if (p.found && std::isfinite(value(p))) {
      lo = std::min(lo, value(p));
      hi = std::max(hi, value(p));
    }
    if (truth != nullptr && p.has_truth && std::isfinite(truth(p))) {
      lo = std::min(lo, truth(p));
      hi = std::max(hi, truth(p));
    }
  }
  if (wraps) {
    lo = -180.0;
    hi = 180.0;
  } else if (!(hi > lo)) {  // none found, or one value: a range around it.
    const double c = hi >= lo ? 0.5 * (lo + hi) : 0.0;
    lo = c - 0.5;
    hi = c + 0.5;
  } else {
    const double pad = 0.08 * (hi - lo);
    lo -= pad;
    hi += pad;
  }
  img.Rectangle(box, kGrid, 1);
  Text(img, series.name, Px(box.x + 6, box.y + 16), 0.45, kText);
  Text(img, FormatNumber("%.3g", hi), Px(box.x + box.width + 4, box.y + 10), 0.38, kLabel);
  Text(img, FormatNumber("%.3g", lo), Px(box.x + box.width + 4, box.y + box.height), 0.38, kLabel);
  const auto at_value = [&](const TrackPoint& p, double v) {
    const double u = time.Share(p.time_s, 0.5);
    const double w = (v - lo) / (hi - lo);
    return Px(box.x + static_cast<int>(std::lround(u * (box.width - 1))),
              box.y + box.height - 1 - static_cast<int>(std::lround(w * (box.height - 1))));
  };
  const auto at = [&](const TrackPoint& p) { return at_value(p, value(p)); };
  // The truth beneath as a broad line, joined while frames with a truth follow one another.
  for (size_t i = 0; truth != nullptr && i < track.size(); ++i) {
    const TrackPoint& p = track[i];
    if (!p.has_truth) continue;
    if (i > 0 && track[i - 1].has_truth &&
        !(wraps && std::abs(truth(p) - truth(track[i - 1])) > 0.5 * (hi - lo))) {
      img.Line(at_value(track[i - 1], truth(track[i - 1])), at_value(p, truth(p)), kTruth, 3,
               LineKind::kSmooth);
    }
  }
  for (size_t i = 0; i < track.size(); ++i) {
    const TrackPoint& p = track[i];
    if (!p.found) continue;
    const Bgr colour = time.Colour(p);
    if (i > 0 && track[i - 1].found &&
        !(wraps && std::abs(value(p) - value(track[i - 1])) > 0.5 * (hi - lo))) {
      img.Line(at(track[i - 1]), at(p), colour, 1, LineKind::kSmooth);
    }
    img.Circle(at(p), 1, colour, -1);
  }
}

}  // namespace

int TrackTopView::Col(double y) const {
  return centre_col - static_cast<int>(std::lround((y - y0) * px_per_m));
}

int TrackTopView::Row(double x) const {
  return centre_row - static_cast<int>(std::lround((x - x0) * px_per_m));
}

TrackTopView FitTrackTopView(const std::vector<TrackPoint>& track) {
  double xmin = 0.0, xmax = 0.0, ymin = 0.0, ymax = 0.0;  // the sensor is always in view.
  bool any = false;
  const auto take = [&](const Pose2D& pose) {
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y)) return;
    any = true;
    xmin = std::min(xmin, pose.x);
    xmax = std::max(xmax, pose.x);
    ymin = std::min(ymin, pose.y);
    ymax = std::max(ymax, pose.y);
  };
  for (const TrackPoint& p : track) {
    if (p.found) take(p.pose);
    if (p.has_truth) take(p.truth);
  }
  // The sensor looks along +x: without a pose to show, the view is of the floor ahead of it.
  if (!any) xmax = kMinViewSpanM - 2 * kViewMarginM;
  TrackTopView v;
  v.x0 = 0.5 * (xmin + xmax);
  v.y0 = 0.5 * (ymin + ymax);
  const double span =
      std::max(kMinViewSpanM, std::max(xmax - xmin, ymax - ymin) + 2 * kViewMarginM);
  v.left = kMargin;
  v.top = kMargin + 20;
  v.size = kTopViewSize;
  v.px_per_m = v.size / span;
  v.centre_col = v.left + v.size / 2;
  v.centre_row = v.top + v.size / 2;
  return v;
}

Status WriteTrackPicture(const std::vector<TrackPoint>& track, const std::string& title,
                         const std::string& path) {
  Result<Canvas> made = Canvas::Create(kTrackPictureWidth, kTrackPictureHeight, kBackground);
  if (!made.ok()) return made.error();
  Canvas& img = *made;
  // The time axis spans every frame's time, in whatever order they came (a stream that looped
  // starts its times again).
  TimeAxis time;
  for (size_t i = 0; i < track.size(); ++i) {
    time.t0 = i == 0 ? track[i].time_s : std::min(time.t0, track[i].time_s);
    time.t1 = i == 0 ? track[i].time_s : std::max(time.t1, track[i].time_s);
  }
  int found = 0, ambiguous = 0, with_truth = 0;
  for (const TrackPoint& p : track) {
    found += p.found ? 1 : 0;
    ambiguous += p.found && p.heading_ambiguous ? 1 : 0;
    with_truth += p.has_truth ? 1 : 0;
  }
  Text(img,
       title + ": " + std::to_string(track.size()) + " frames over " +
           FormatNumber("%.1f", time.t1 - time.t0) + " s, humanoid in " + std::to_string(found) +
           " (heading ambiguous in " + std::to_string(ambiguous) + ")",
       Px(kMargin, kMargin + 4), 0.55, kText);

  const TrackTopView view = FitTrackTopView(track);
  DrawTopView(img, view, track, time, found);

  // The charts right of the top view, then the strip of frames found.
  const int left = view.left + view.size + 30;
  const int width = kTrackPictureWidth - left - 70;
  const int top = view.top;
  const int gap = 14, strip = 14;
  const int height = (view.size - strip - 4 * gap) / 4;
  const auto box = [&](int i) { return PxBox{left, top + i * (height + gap), width, height}; };
  for (int i = 0; i < 4; ++i) DrawChart(img, box(i), kSeries[i], track, time);
  const int strip_top = top + 4 * (height + gap);
  for (size_t i = 0; i < track.size(); ++i) {
    const double u = time.Share(track[i].time_s, 0.5);
    const int x = left + static_cast<int>(std::lround(u * (width - 1)));
    img.Line(Px(x, strip_top), Px(x, strip_top + strip - 1),
             track[i].found ? kFoundStrip : kMissedStrip, 1);
  }
  img.Rectangle(PxBox{left, strip_top, width, strip}, kGrid, 1);
  Text(img, "found", Px(left + width + 4, strip_top + 11), 0.38, kLabel);
  Text(img,
       "time " + FormatNumber("%.1f", 0.0) + " .. " + FormatNumber("%.1f s", time.t1 - time.t0) +
           " (blue .. red); orange arrows: heading ambiguous" +
           (with_truth > 0 ? "; pale green: the truth" : ""),
       Px(left, strip_top + strip + 16), 0.4, kLabel);
  return WritePicturePng(img, path);
}

}  // namespace hpose::tools
