//! The integration tests, one module per topic. They are one test crate so that the
//! draw loops they instantiate (their own shaders and colour targets) are compiled
//! and linked once, not once per file.

mod common;

mod accuracy;
mod bench_runs;
mod bytes;
mod cli_mistakes;
mod cli_raster;
mod colour_pipelines;
mod coverage;
mod formats;
mod framing;
mod gltf;
mod glyphs;
mod hard_cases;
mod input;
mod lines;
mod link;
mod mesh;
mod model_frames;
mod obj_files;
mod pipeline;
mod scenes;
mod serve;
mod terminal;
mod threads;
mod tmux;
mod wire;
