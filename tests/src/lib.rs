//! System tests: they launch the real binaries (built first, found under `target/`) and couple
//! them over shared memory. The library holds what the tests share; `src/bin/` holds test-only
//! participants.
