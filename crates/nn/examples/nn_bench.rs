//! Prints the nn crate's LSTM throughput table: `cargo run -p inbetween-nn --example nn_bench`.
//! Pass `--smoke` for tiny sizes.

fn main() {
    let smoke = std::env::args().any(|a| a == "--smoke");
    let opts = if smoke {
        inbetween_nn::bench::LstmBenchOptions::smoke()
    } else {
        inbetween_nn::bench::LstmBenchOptions::default()
    };
    let mut rows = inbetween_nn::bench::lstm_throughput(&opts);
    // The same LSTM size stepped by the plain-Rust runtime layers (what camera inference uses).
    let (batch, frames) = if smoke { (2, 8) } else { (opts.batch, opts.frames) };
    rows.push(inbetween_nn::bench::lstm_runtime_throughput(opts.hidden, opts.d_input, batch, frames, 3));
    print!("{}", inbetween_nn::bench::table(&rows).to_text());
}
