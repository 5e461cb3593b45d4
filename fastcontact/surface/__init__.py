"""fastcontact.surface."""
