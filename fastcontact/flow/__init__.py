"""fastcontact.flow."""
