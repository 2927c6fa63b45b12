#ifndef HPOSE_SERVER_OPENNI2_FILE_PLAYER_H_
#define HPOSE_SERVER_OPENNI2_FILE_PLAYER_H_

namespace openni {
class Device;
class VideoStream;
}  // namespace openni

namespace hpose::server {

// Makes closing `device` safe when it is an open recording from which no frame has come yet.
//
// OpenNI2's file player marks itself running in its own thread, first thing. A recording closed
// before that thread has run (opened for its frame count only, or refused at once: no depth in
// it) has the player mark itself running after the close asked it to stop: it spins, OpenNI2
// cancels it 3 s later, and the cancelled thread crashes unwinding through its driver once
// OpenNI2's shutdown has unloaded it. A frame delivered shows the thread has run, so this waits
// (up to 3 s) for one: from `stream` when valid (started if it was not), else from the first
// stream the recording has. Does nothing for a live device.
void LetTheFilePlayerStart(openni::Device& device, openni::VideoStream* stream);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_OPENNI2_FILE_PLAYER_H_
