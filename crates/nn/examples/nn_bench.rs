//! Prints the nn crate's LSTM throughput table: `cargo run -p inbetween-nn --example nn_bench`.
//! Pass `--smoke` for tiny sizes.

fn main() {
    let smoke = std::env::args().any(|a| a == "--smoke");
    let opts = if smoke {
        inbetween_nn::bench::LstmBenchOptions::smoke()
    } else {
        inbetween_nn::bench::LstmBenchOptions::default()
    };
    let rows = inbetween_nn::bench::lstm_throughput(&opts);
    print!("{}", inbetween_nn::bench::format_table(&rows));
}
