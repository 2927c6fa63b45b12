#ifndef HPOSE_TOOLS_DRAWING_DRAWING_API_H_
#define HPOSE_TOOLS_DRAWING_DRAWING_API_H_

#include <cstddef>
#include <cstdint>

// The boundary between the programs and the drawing module (hpose-drawing.so), which the
// programs load only when they draw a picture: OpenCV's core and imgproc (and the X11, OpenGL,
// LAPACK and threading libraries they bring) then cost nothing to a run that draws none. Plain C
// types only, so that the module is free of hpose's own libraries.
extern "C" {

// Eight-bit blue, green, red pixels, `stride` bytes from one row to the next.
struct HposeDrawTarget {
  std::uint8_t* bgr;
  int width;
  int height;
  std::size_t stride;
};

// Line kinds, as in OpenCV: 8-connected, or anti-aliased.
enum { kHposeLine8 = 8, kHposeLineAntialiased = 16 };
// Marker shapes.
enum { kHposeMarkerCross = 0, kHposeMarkerTriangleUp = 1 };

// Each function draws clipped to the target; `colour` is blue, green, red in 0..255; a
// negative thickness fills the shape. Text is in OpenCV's simplex Hershey font, `x`, `y` its
// baseline's left end.
struct HposeDrawingApi {
  std::uint32_t version;  // kHposeDrawingApiVersion.
  std::uint32_t size;     // sizeof(HposeDrawingApi) when the module was built.
  void (*line)(const HposeDrawTarget* target, int x0, int y0, int x1, int y1, const double* colour,
               int thickness, int kind);
  void (*circle)(const HposeDrawTarget* target, int x, int y, int radius, const double* colour,
                 int thickness, int kind);
  // The rectangle with opposite corners (x0, y0) and (x1, y1), both drawn.
  void (*rectangle)(const HposeDrawTarget* target, int x0, int y0, int x1, int y1,
                    const double* colour, int thickness, int kind);
  void (*arrowed_line)(const HposeDrawTarget* target, int x0, int y0, int x1, int y1,
                       const double* colour, int thickness, int kind, double tip_length);
  void (*marker)(const HposeDrawTarget* target, int x, int y, const double* colour, int shape,
                 int size, int thickness);
  void (*text)(const HposeDrawTarget* target, const char* text, int x, int y, double scale,
               const double* colour, int thickness, int kind);
  // The size of `text` drawn by `text`: width and height above the baseline, and the depth
  // below it.
  void (*text_size)(const char* text, double scale, int thickness, int* width, int* height,
                    int* baseline);
};

enum { kHposeDrawingApiVersion = 1 };

// The module's one exported function.
const HposeDrawingApi* hpose_drawing_api_v1(void);
typedef const HposeDrawingApi* (*HposeDrawingApiFunction)(void);

}  // extern "C"

#endif  // HPOSE_TOOLS_DRAWING_DRAWING_API_H_
