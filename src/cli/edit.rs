//! `btfsm edit`: the paper's edit operations.

use super::args::EditArgs;

pub fn edit(_a: &EditArgs) -> u8 {
    super::EXIT_BAD_INPUT
}
