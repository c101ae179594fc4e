// Detumble: enable the magnetorquer, command a dipole, check it, then degauss the cores.
procedure
  main
    initiate and confirm step Command
      main
        initiate and confirm enable of Magnetorquer;
        initiate and confirm set_dipole of Magnetorquer
          with arguments x := 0.1, y := -0.05, z := 0.0 end with;
        wait until dipole_x of Magnetorquer > 0.09 A.m^2 timeout 5 s;
        log "dipole x: ", dipole_x of Magnetorquer;
      end main
    end step;
    initiate and confirm step Degauss
      main
        initiate and confirm degauss of Magnetorquer;
      end main
    end step;
    inform user "magnetorquer detumble pulse done";
  end main
end procedure
