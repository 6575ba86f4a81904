"""The paper's procedures and the demo: muscle calibration, the compliance experiment, the
scripted demo run (`mimo-social calibrate | compliance | demo`)."""
