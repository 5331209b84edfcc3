//! Material: the generalized Maxwell (Prony) solid, the WLF shift of relaxation times, cross-section
//! stiffnesses and the internal-variable updates.
