// Switch CPDU lines through the nominal controller and confirm the new state.
procedure
  main
    initiate and confirm set_state_bits of CpduN with arguments state := 5 end with;
  end main
end procedure
