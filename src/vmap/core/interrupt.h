#pragma once
// SIGINT, SIGTERM and SIGHUP end vmap without leaving its temporary outputs behind.
//
// Nothing runs inside a signal handler. InstallInterruptHandling() blocks these signals in the calling thread,
// and so in every thread started after it, and starts one thread that waits for them with sigwait(). When one
// arrives, that thread, as ordinary code, removes every temporary output still registered (atomic_output.h;
// a commit in progress finishes first) and ends the process with status 128 + the signal's number, as shells
// report it (130 for SIGINT, 143 for SIGTERM). Whatever the other threads were doing, the final outputs are
// either the old ones or the new ones: they only ever appear by a rename.
//
// A signal that the process was started with ignored (nohup, `cmd &` in a script) stays ignored.
//
// InitializeRuntime() (runtime.h) calls this once, first thing in main(), before any other thread exists; the
// library never installs it, so a program that embeds vmap keeps its own signal handling.
//
// A live run (`vmap build --until-interrupted`) lets SIGINT end its input instead: while EndInputOnSigint is
// on, the first SIGINT only sets InputEndRequested(), and the run finishes its map from the frames it saw; a
// second SIGINT, SIGTERM or SIGHUP still ends the process as above.

namespace vmap {

void InstallInterruptHandling();

// Turns the graceful SIGINT on or off (off by default). Safe from any thread.
void EndInputOnSigint(bool enabled);
// Whether a SIGINT asked to end the input since EndInputOnSigint(true). Safe from any thread, cheap to poll.
bool InputEndRequested();

}  // namespace vmap
