// Deploy the solar panel, then turn it to 30 degrees and wait until it is there.
procedure
  main
    initiate and confirm step Deploy
      main
        log "angle before: ", angle of SolarPanel;
        initiate and confirm deploy of SolarPanel;
      end main
    end step;
    initiate and confirm step Turn
      main
        initiate and confirm set_angle of SolarPanel with arguments angle := 30 deg end with;
        wait until angle of SolarPanel > 29.5 deg timeout 5 s;
        log "angle after: ", angle of SolarPanel;
      end main
    end step;
    inform user "solar panel deployed and at 30 deg";
  end main
end procedure
