//! Graph edit distance (paper sec. IV-A 2, Eq. 2) on directed multigraphs with
//! self-loops, unit costs. Work in progress.
