//! Cuts the first messages of every topic out of a ROS 1 bag (format 2.0, uncompressed
//! chunks) into a small indexed bag: how `tests/data/laser2d/positive_1_excerpt.bag` was
//! made from the `leg_tracker` recording of `../shared/data/laser2d/leg_annotated`:
//!
//! ```text
//! cargo run --example cut_bag -- ../shared/data/laser2d/leg_annotated/positive_1_extracted.bag \
//!     tests/data/laser2d/positive_1_excerpt.bag --messages 39 --chunk-threshold 65536
//! ```
//!
//! Messages and connection records are copied byte for byte; chunks, index and bag header
//! are written anew (layout: `excerpt.rs`). The output is a function of the input and the
//! options alone, so the command reproduces the file exactly.

use anyhow::{Context, Result};
use clap::Parser;
use std::path::PathBuf;

mod excerpt;

#[derive(Parser, Debug)]
#[command(about = "Cut the first messages of every topic out of a ROS 1 bag")]
struct Args {
    /// The source bag.
    source: PathBuf,
    /// The excerpt to write.
    out: PathBuf,
    /// Messages kept per topic (connection), the first in storage order.
    #[arg(long, default_value_t = 32)]
    messages: usize,
    /// A chunk is closed once its data exceeds this many bytes (ROS records 768 KiB chunks;
    /// a smaller threshold gives a small excerpt several chunks).
    #[arg(long, default_value_t = 768 * 1024)]
    chunk_threshold: usize,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let source = std::fs::read(&args.source)
        .with_context(|| format!("reading {}", args.source.display()))?;
    let bag = excerpt::cut(
        &source,
        excerpt::CutOptions {
            messages: args.messages,
            chunk_threshold: args.chunk_threshold,
        },
    )
    .map_err(anyhow::Error::msg)
    .with_context(|| format!("cutting {}", args.source.display()))?;
    std::fs::write(&args.out, &bag).with_context(|| format!("writing {}", args.out.display()))?;
    println!("{}: {} bytes", args.out.display(), bag.len());
    Ok(())
}
