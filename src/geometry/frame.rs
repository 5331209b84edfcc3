//! Rotation-minimising section frames along a curve and the reference curvature `K0` and `K0,s`.
