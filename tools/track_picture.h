#ifndef HPOSE_TOOLS_TRACK_PICTURE_H_
#define HPOSE_TOOLS_TRACK_PICTURE_H_

#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/common/status.h"

namespace hpose::tools {

// One frame of a replayed recording, as the track picture draws it.
struct TrackPoint {
  double time_s = 0.0;  // the frame's source time.
  bool found = false;   // a humanoid passed in this frame (its pose and score below).
  Pose2D pose;          // ground frame.
  double score = 0.0;
  bool heading_ambiguous = false;
  bool has_truth = false;  // where the humanoid truly stood is known (a simulation's truth) ...
  Pose2D truth;            // ... and is this, ground frame.
};

// Where the track picture's top view draws a ground point: pixel = centre - (y, x) * scale
// from the ground point at its centre (+x up the picture, +y to the left).
struct TrackTopView {
  double x0 = 0.0, y0 = 0.0;  // the ground point at the view's centre, metres.
  double px_per_m = 1.0;
  int centre_col = 0, centre_row = 0;
  int left = 0, top = 0, size = 0;  // the square panel in the picture, pixels.

  int Col(double y) const;
  int Row(double x) const;
};

// The top view that shows the sensor (the ground frame's origin) and every found pose and truth
// of `track`, with a margin; without either, the floor ahead of the sensor.
TrackTopView FitTrackTopView(const std::vector<TrackPoint>& track);

// Draws a replay's track for people: left, the floor from above (the sensor at the origin, +x
// up, +y left, a grid) with the humanoid's path coloured from its first frame (blue) to its
// last (red), its heading every few frames (orange where it was ambiguous), the start (circle)
// and the end (square); right, x, y, heading and score against time, with gaps where no
// humanoid was found, and a strip of the frames found (green) and not (red). Where frames have
// a truth it is drawn beneath, in pale green: the true path in the top view, the true x, y and
// heading in the charts. `title` heads it. A track without any humanoid found is drawn too, and
// says so.
Status WriteTrackPicture(const std::vector<TrackPoint>& track, const std::string& title,
                         const std::string& path);

// The picture's size, pixels.
constexpr int kTrackPictureWidth = 1280;
constexpr int kTrackPictureHeight = 720;

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_TRACK_PICTURE_H_
