"""fastcontact._core."""
