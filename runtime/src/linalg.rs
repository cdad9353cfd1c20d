//! Allocation-free fixed-size linear algebra for generated observers (being written).
