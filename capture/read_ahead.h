// A FrameSource read on a thread of its own, a few frames ahead of the caller, so that decoding
// overlaps the work done with each frame (daylit's pipeline controller reads through it).
#pragma once

#include <memory>

#include "capture/frame_source.h"

namespace daylit::capture {

// `source`'s frames in order, up to `depth` (1..64) decoded ahead. Next() never returns kWaiting:
// while a live camera is gone it blocks until a frame, an unreadable frame or the end comes. An
// error thrown by `source` is rethrown by the Next() that reaches it. A recording's reader waits
// while `depth` frames wait; a live camera's never does (the driver would drop frames for want of
// a queued buffer): the oldest waiting frame is given up instead, counted in stats().skipped.
// waiting() is the queue's length. Seek() is not offered (a
// read-ahead cannot take back what it has read): InvariantError. Destroying it mid-stream stops
// the thread after the frame it is reading.
std::unique_ptr<FrameSource> ReadAhead(std::unique_ptr<FrameSource> source, int depth = 4);

}  // namespace daylit::capture
