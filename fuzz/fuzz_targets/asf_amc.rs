//! ASF/AMC reader on arbitrary bytes: must never panic. Input up to the first NUL byte is the ASF,
//! the rest the AMC; without a NUL the input is tried in each role beside a small valid partner.
#![no_main]

use inbetween_io::asf::parse_asf_amc;
use libfuzzer_sys::fuzz_target;

const ASF: &str = ":units\n angle deg\n:root\n order TX TY TZ RX RY RZ\n axis XYZ\n position 0 0 0\n orientation 0 0 0\n:bonedata\n begin\n  name a\n  direction 0 1 0\n  length 2\n  axis 0 0 30 XYZ\n  dof rx rz\n end\n:hierarchy\n begin\n  root a\n end\n";
const AMC: &str = ":FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 1 2 3 4 5\na 10 20\n";

fuzz_target!(|data: &[u8]| {
    match data.iter().position(|&b| b == 0) {
        Some(split) => {
            let asf = String::from_utf8_lossy(&data[..split]);
            let amc = String::from_utf8_lossy(&data[split + 1..]);
            let _ = parse_asf_amc(&asf, &amc, "fuzz.asf", "fuzz.amc");
        }
        None => {
            let text = String::from_utf8_lossy(data);
            let _ = parse_asf_amc(&text, AMC, "fuzz.asf", "seed.amc");
            let _ = parse_asf_amc(ASF, &text, "seed.asf", "fuzz.amc");
        }
    }
});
