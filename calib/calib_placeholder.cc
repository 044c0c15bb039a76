// The calibration issue (8) fills this library.
