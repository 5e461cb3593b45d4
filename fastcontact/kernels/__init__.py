"""fastcontact.kernels."""
